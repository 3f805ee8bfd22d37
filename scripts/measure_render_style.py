"""Measure the rendering style on the viewer's own exports: white level of the zero band
facing the viewer and colour saturation, for a Laplacian mode of a mesh.

    python scripts/measure_render_style.py [MESH] [--mode 6] [--style paper|shaded] [-o DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("MODALVIEWER_NO_DIALOGS", "1")
# a settings file of its own: the measurement changes the isoline count
os.environ.setdefault("MODALVIEWER_SETTINGS", "/tmp/modalviewer-measure-settings.ini")
if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np  # noqa: E402
from qtpy import QtWidgets  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh", nargs="?", default=str(ROOT / "assets" / "spot.obj"))
    ap.add_argument("--mode", type=int, default=6)
    ap.add_argument("--operator", default="laplacian")
    ap.add_argument("--style", default=None)
    ap.add_argument("-o", "--out", default="/tmp")
    args = ap.parse_args()
    from PIL import Image

    from modalviewer.gui import MainWindow
    from modalviewer.gui.render_metrics import saturation, white_level, zero_band_masks

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    win = MainWindow()
    win.resize(1280, 800)
    win.show()
    app.processEvents()
    win.open_mesh(args.mesh)
    win.compute(args.operator, k=max(20, args.mode + 1), wait=True)
    if args.style and hasattr(win.scene, "set_style"):
        win.scene.set_style(args.style)
    win.show_mode(args.mode)
    field = np.array(win.scene.surface.point_data["field"])
    name = f"{Path(args.mesh).stem}_{args.operator}_{args.mode}_{args.style or 'default'}"
    out = Path(args.out)
    lines = win.export_screenshot(out / f"{name}_lines.png")
    win.iso_spin.setValue(0)
    path = win.export_screenshot(out / f"{name}.png")
    img = np.asarray(Image.open(path))[:, :, :3]
    mesh, band = zero_band_masks(win.scene, field)
    result = {
        "mesh": Path(args.mesh).name,
        "mode": args.mode,
        "style": args.style or "default",
        "white_level_zero_band": white_level(img, band),
        "white_level_mesh_p95": white_level(img, mesh)["p95"],
        "saturation": saturation(img, mesh),
        "images": [str(lines), str(path)],
    }
    print(json.dumps(result, indent=1))
    win.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
