"""The README figure of the shape pair window: a pick on the middle fingertip of
``assets/demo_hand.obj`` and its matches on ``assets/demo_hand_bent.obj``, under the
vibration and the heat kernel distance, exported by the pair window itself.

    python scripts/pair_figure.py [--k 100] [--scale 1]

Writes ``screenshots/pair_hand_vibration.png`` and ``screenshots/pair_hand_hks.png`` and
prints how long each step took.  Spectra come from the viewer's disk cache
(``$MODALVIEWER_CACHE``) when present; the window's defaults apply (both meshes
rescaled to unit area before computing); the threshold display marks the 3 % of
B's area closest to the pick.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, default=100)
    parser.add_argument("--scale", type=int, default=1)
    parser.add_argument("--share", type=float, default=0.03, help="threshold share of B")
    args = parser.parse_args()
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    os.environ.setdefault("MODALVIEWER_NO_DIALOGS", "1")
    from qtpy import QtWidgets

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    from modalviewer.gui import MainWindow

    landmarks = json.loads((ROOT / "assets" / "demo_landmarks.json").read_text())
    tips_b = landmarks["demo_hand_bent"]
    pick = landmarks["demo_hand"]["finger1"]  # the middle fingertip (bent on B)
    win = MainWindow(remember_settings=False)
    win.resize(1000, 700)
    win.show()
    started = time.perf_counter()
    win.open_mesh(ROOT / "assets" / "demo_hand.obj")
    win.state.set_display(distance_kind="vibration")
    pair = win.open_second_mesh(ROOT / "assets" / "demo_hand_bent.obj", wait=False, k=args.k)
    pair.resize(1240, 600)
    app.processEvents()
    print(f"open both meshes and the window: {time.perf_counter() - started:.1f} s")
    # seen from the palm side, so the bent fingertip shows; B follows A (linked)
    pair.pair.linked = False
    for side in ("a", "b"):
        plotter = pair.viewports[side].plotter
        plotter.view_xy()
        plotter.camera.Azimuth(155.0)
        plotter.camera.Elevation(35.0)
        plotter.camera.OrthogonalizeViewUp()
        plotter.reset_camera()
    pair.pair.linked = True
    pair.pair.set_display("threshold", share=args.share)
    for kind in ("vibration", "hks"):
        t = time.perf_counter()
        pair.pair.kind = kind
        pair.wait()
        print(f"{kind}: spectra of both meshes {time.perf_counter() - t:.1f} s")
        t = time.perf_counter()
        pair.pair.pick("a", pick)
        app.processEvents()
        side, w, dist = pair.pair.best_match()
        print(f"{kind}: pick and draw {time.perf_counter() - t:.2f} s")
        near = min(tips_b, key=lambda n: float(
            ((pair.pair.mesh("b").vertices[w] - pair.pair.mesh("b").vertices[tips_b[n]]) ** 2).sum()
        ))  # fmt: skip
        print(f"{kind}: best match on B vertex {w} (d = {dist:.3g}), nearest landmark {near}; "
              f"back match on A {pair.pair.back_match()}")  # fmt: skip
        t = time.perf_counter()
        out = pair.export_screenshot(ROOT / "screenshots" / f"pair_hand_{kind}.png", args.scale)
        print(f"{kind}: export {time.perf_counter() - t:.2f} s -> {out.relative_to(ROOT)}")
    pair.close()
    win.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
