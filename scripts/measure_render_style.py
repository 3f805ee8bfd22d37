"""Measure the rendering styles on exported screenshots: the white level of the zero band
facing the viewer and the colour saturation, for Laplacian modes of a mesh, both styles in
the same (canonical) view.

    python scripts/measure_render_style.py [MESH ...] [--modes 1 6] [-o DIR]

Zero band: |phi| < 5 % of max |phi| on vertices whose normal is within 45 degrees of the
direction to the camera; white level: percentiles of min(R, G, B) over its pixels;
saturation: shares of the mesh's pixels with blue 60 above red / red 80 above blue.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("meshes", nargs="*", default=[str(ROOT / "assets" / "spot.obj")])
    ap.add_argument("--modes", type=int, nargs="+", default=[1, 6])
    ap.add_argument("--size", default="800x700")
    ap.add_argument("-o", "--out", default=None, help="folder for the exported PNGs")
    args = ap.parse_args()
    import pyvista as pv
    from PIL import Image

    import modalviewer as mv
    from benchmarks.render_metrics import saturation, white_level, zero_band_masks
    from modalviewer.core.laplacian import vertex_normals
    from modalviewer.scene.colors import STYLES
    from modalviewer.scene.export import grab, save_png
    from modalviewer.scene.mesh_scene import MeshScene

    out = Path(args.out) if args.out else Path(os.environ.get("TMPDIR", "/tmp"))
    w, h = (int(x) for x in args.size.split("x"))
    for path in args.meshes:
        mesh = mv.load_mesh(path)
        spec = mv.compute_spectrum(mesh, "laplacian", k=max(args.modes) + 1)
        plotter = pv.Plotter(off_screen=True, window_size=(w, h))
        plotter.set_background("white")
        plotter.show(auto_close=False, interactive=False)
        scene = MeshScene(plotter, mesh, vertex_normals(mesh))
        scene.reset_camera()
        for j in args.modes:
            field = spec.mode(j)
            for style in STYLES:
                scene.set_style(style)
                scene.show_field(field, "diverging", isolines=0)
                png = save_png(out / f"{Path(path).stem}_mode{j}_{style}.png", grab(plotter))
                img = np.asarray(Image.open(png))[:, :, :3]
                mesh_px, band = zero_band_masks(scene, field)
                wl, sat = white_level(img, band), saturation(img, mesh_px)
                print(
                    f"{Path(path).name:24s} mode {j:2d} {style:6s} zero band {wl['n']:6d} px: "
                    f"min(R,G,B) p5 {wl['p5']:.0f} p50 {wl['p50']:.0f} p95 {wl['p95']:.0f}; "
                    f"blue {100 * sat['blue']:.1f} %, orange {100 * sat['orange']:.1f} %"
                )
        plotter.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
