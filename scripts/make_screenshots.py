"""Regenerate the README screenshots with the viewer's own export (runs off-screen)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("MODALVIEWER_NO_DIALOGS", "1")
if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

from qtpy import QtWidgets  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "screenshots"


def main() -> int:
    from modalviewer.gui import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    win = MainWindow()
    win.resize(1500, 900)
    win.show()
    app.processEvents()
    win.open_mesh(ROOT / "assets" / "spot.obj")
    win.compute("laplacian", k=30, wait=True)
    win.show_mode(9)
    win.export_screenshot(OUT / "viewer_laplacian_mode.png", colorbar=True)
    win.compute("modified_dirichlet", k=30, wait=True)
    win.show_mode(9)
    win.export_screenshot(OUT / "viewer_dirichlet_mode.png")
    win.compute("shells", k=60, wait=True)
    win.pick_vertex(2000)
    win.show_distance("vibration", display="continuous")
    win.export_screenshot(OUT / "viewer_vibration_distance.png", colorbar=True)
    win.show_distance("vibration", display="threshold", share=0.15)
    win.export_screenshot(OUT / "viewer_vibration_threshold.png", colorbar=True)
    win.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
