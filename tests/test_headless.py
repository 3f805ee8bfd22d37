"""The library, the Viewer and the command line's pictures with Qt unimportable.

Each test runs in a fresh Python process in which importing qtpy, PySide6 or
pyvistaqt raises ImportError, as on a machine without Qt.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPOT = ROOT / "assets" / "spot.obj"

BLOCK_QT = """
import sys
for name in ("qtpy", "PySide6", "PyQt5", "PyQt6", "pyvistaqt"):
    sys.modules[name] = None  # import raises ImportError
"""


def _python(code: str, tmp_path, timeout: float = 600, **env_vars) -> subprocess.CompletedProcess:
    env = dict(os.environ, MODALVIEWER_CACHE=str(tmp_path / "cache"), **env_vars)
    env.pop("QT_QPA_PLATFORM", None)
    return subprocess.run(
        [sys.executable, "-c", BLOCK_QT + code],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=tmp_path,
        env=env,
    )


def test_importing_the_library_and_the_viewer_loads_no_qt_and_no_vtk(tmp_path):
    code = """
import modalviewer as mv, modalviewer.viewer
viewer = mv.Viewer()
heavy = sorted(m for m in sys.modules if m.split(".")[0] in ("vtkmodules", "pyvista", "vtk")
               or m.startswith("modalviewer.gui") or m.startswith("modalviewer.scene"))
print("loaded:", heavy)
"""
    run = _python(code, tmp_path)
    assert run.returncode == 0, run.stderr
    assert "loaded: []" in run.stdout


def _colours(path) -> dict[str, int]:
    from PIL import Image

    rgb = np.asarray(Image.open(path))[:, :, :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return {
        "blue": int(np.sum((b > r + 60) & (b > g + 20))),
        "orange": int(np.sum((r > b + 80) & (g > b + 20))),
        "pixels": r.size,
    }


def test_render_and_distance_pictures_without_qt(tmp_path):
    code = f"""
from modalviewer.cli import main
spot = {str(SPOT)!r}
assert main(["render", spot, "--operator", "laplacian", "--mode", "6", "-k", "12",
             "--size", "400x300", "-o", "mode.png"]) == 0
assert main(["distance", spot, "--vertex", "100", "--kind", "hks", "-k", "30",
             "--share", "0.1", "--size", "400x300", "-o", "map.png"]) == 0
print("gui loaded:", any(m.startswith("modalviewer.gui") for m in sys.modules))
"""
    run = _python(code, tmp_path)
    assert run.returncode == 0, run.stderr
    assert "gui loaded: False" in run.stdout
    assert "wrote mode.png (PNG 400x300, mode 6)" in run.stdout
    mode = _colours(tmp_path / "mode.png")
    assert mode["blue"] > 300 and mode["orange"] > 300, mode
    assert "10.0" in run.stdout.split("threshold")[-1]  # "10.0x %" of the area marked
    blue = _colours(tmp_path / "map.png")["blue"]
    # a tenth of the area in blue: a few per cent of the picture's pixels
    assert 0.003 < blue / (400 * 300) < 0.2, blue


def test_the_viewer_flows_run_with_qt_unimportable(tmp_path):
    code = f"""
import pytest
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", "--rootdir", {str(ROOT)!r},
                      {str(ROOT / "tests" / "viewer" / "test_viewer_flows.py")!r}]))
"""
    # no plugin autoloading: pytest-qt would import Qt on start
    run = _python(code, tmp_path, timeout=900, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert " passed" in run.stdout and "failed" not in run.stdout
