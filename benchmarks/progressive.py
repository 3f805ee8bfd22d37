"""The viewer's progressive display on a big mesh: preview first, exact after.

    python -m benchmarks.progressive [--size 130k] [--operator laplacian|shells|...] [--k 100]

Off-screen window, empty cache.  The user asks for a spectrum, looks at mode 10 as soon
as something is on screen, picks a vertex and switches to a threshold map of the
distance; the exact spectrum then replaces the preview.  Measured: seconds until the
preview is on screen and until the exact spectrum is, the longest event-loop gaps while
waiting for each (the benchmark's own pick and export excluded), and
whether the display (mode, pick, map) survived the replacement; the distances drawn from
the preview and from the exact spectrum are compared.  Screenshots of both are saved in
benchmarks/results/ next to the JSON.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import make_mesh, save_result  # noqa: E402
from benchmarks.window import EventLoopGaps, bench_window  # noqa: E402
from modalviewer.core.operators import OPERATOR_INFO  # noqa: E402

KIND = {name: info.distance_kind for name, info in OPERATOR_INFO.items() if info.distance_kind}
"""The distance each operator's spectrum defines (the registry's)."""


def run(size: str, operator: str, k: int) -> dict:
    app, win = bench_window()
    mesh = make_mesh(size)
    win.set_mesh(mesh)
    win.viewport.render_now()
    out = {"mesh": size, "vertices": mesh.n_vertices, "operator": operator, "k": k}
    clock = EventLoopGaps()
    state = win.state
    started = time.perf_counter()
    job = win.compute(operator, k=k, wait=False)  # noqa: F841 (the window keeps it)
    while state.spectrum(operator) is None:
        app.processEvents()
        time.sleep(0.005)
    preview = state.spectrum(operator)
    out["preview_on_screen_s"] = time.perf_counter() - started
    out["first_spectrum_is_preview"] = bool(preview.is_preview)
    out["preview_estimated_error"] = preview.estimated_error
    win.show_mode(10)
    vertex = mesh.n_vertices // 3
    state.set_display(distance_kind=KIND[operator])
    win.pick_vertex(vertex)
    win.show_distance(display="threshold")  # a first threshold map marks a tenth
    app.processEvents()
    preview_map = state.derived.distance_map().copy()
    stem = f"progressive_{size}" + ("" if operator == "laplacian" else f"_{operator}")
    win.export_screenshot(ROOT / "benchmarks" / "results" / f"{stem}_preview.png")
    display_before = state.display
    share_before = state.derived.marked_share()
    waiting_gaps = clock.reset()  # the gaps while nothing but waiting ran
    while state.spectrum(operator).is_preview:
        app.processEvents()
        time.sleep(0.005)
    out["exact_on_screen_s"] = time.perf_counter() - started
    app.processEvents()
    clock.stop()
    exact = state.spectrum(operator)
    exact_map = state.derived.distance_map()
    # the threshold follows the map to keep its share of the surface: compared as a share
    kept = replace(state.display, threshold=display_before.threshold) == display_before
    out["display_kept"] = bool(kept and state.picked == vertex)
    out["threshold_share_preview_exact"] = [share_before, state.derived.marked_share()]
    out["distance_correlation_preview_exact"] = float(np.corrcoef(preview_map, exact_map)[0, 1])
    nonzero = ~exact.zero_mode_mask()
    rel = (preview.eigenvalues[nonzero][:50] - exact.eigenvalues[nonzero][:50]) / np.abs(
        exact.eigenvalues[nonzero][:50]
    )
    out["eigenvalue_error_lowest_50_max"] = float(rel.max())
    out["longest_event_loop_gap_ms_until_preview"] = 1e3 * float(max(waiting_gaps))
    out["longest_event_loop_gap_ms_until_exact"] = 1e3 * float(max(clock.gaps))
    win.export_screenshot(ROOT / "benchmarks" / "results" / f"{stem}_exact.png")
    win.close()
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", default="130k")
    p.add_argument("--operator", default="laplacian", choices=sorted(KIND))
    p.add_argument("-k", "--k", type=int, default=100)
    args = p.parse_args(argv)
    out = run(args.size, args.operator, args.k)
    for key, value in out.items():
        print(f"{key:38s} {value}")
    save_result(f"progressive_{args.size}_{args.operator}", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
