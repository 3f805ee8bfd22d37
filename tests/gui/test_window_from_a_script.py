"""A window made from a plain script or notebook, with no QApplication, no
QT_QPA_PLATFORM and no display: it starts (off screen), shows what an existing Viewer
shows, and its pictures are real renders."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.gui

ROOT = Path(__file__).resolve().parents[2]


def test_main_window_starts_from_a_script_without_an_application(tmp_path):
    script = f"""
import numpy as np
import modalviewer as mv
from modalviewer.gui import MainWindow

viewer = mv.Viewer()
viewer.open_mesh({str(ROOT / "assets" / "spot.obj")!r})
spec = viewer.compute("laplacian", k=12)
viewer.show_mode(6)
win = MainWindow(viewer=viewer)        # no QApplication made by the script
assert win.viewer is viewer and win.mesh is viewer.mesh
assert win.modes_panel.mode_spin.value() == 6
name, values = win.current_field()
np.testing.assert_allclose(values, spec.mode(6), atol=1e-12)
win.resize(800, 600)
win.show()
out = win.export_screenshot("win.png")
from qtpy import QtGui
print("platform:", QtGui.QGuiApplication.platformName())
win.close()
print("wrote", out)
"""
    env = dict(os.environ, MODALVIEWER_CACHE=str(tmp_path / "cache"))
    for name in ("QT_QPA_PLATFORM", "DISPLAY", "WAYLAND_DISPLAY"):
        env.pop(name, None)
    env["MODALVIEWER_SETTINGS"] = str(tmp_path / "settings.ini")
    run = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert "platform: offscreen" in run.stdout
    from PIL import Image

    rgb = np.asarray(Image.open(tmp_path / "win.png"))[:, :, :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    blue = np.sum((b > r + 60) & (b > g + 20))
    orange = np.sum((r > b + 80) & (g > b + 20))
    assert blue > 300 and orange > 300, (blue, orange)
