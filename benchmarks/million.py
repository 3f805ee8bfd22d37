"""A million vertices in the viewer's window: open, draw, pick, compute, responsive.

    python -m benchmarks.million [--grid 1000] [-k 100]

The real main window, off-screen (software OpenGL), empty cache, on the bumpy plate of a
1000 x 1000 grid (1 000 000 vertices).  Measured: seconds to set the mesh and draw it;
for the Laplacian's exact spectrum, then a pick and its heat kernel distance map: what
the viewer said (its status line), seconds until the spectrum was on screen, the
progress stages seen, the longest gap of the event loop while computing (a
10 ms timer: the window stays responsive when it is short) and the computing process's
peak memory.  Writes ``benchmarks/results/million.json`` and screenshots beside it.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import save_result  # noqa: E402
from benchmarks.window import EventLoopGaps, bench_window  # noqa: E402


def _children_peak_mb() -> float:
    """The largest peak resident memory of the finished child processes (the job
    processes that computed)."""
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024


def _rounded(ms: float | None) -> float | None:
    return None if ms is None else round(ms, 1)


def run(grid: int, k: int) -> dict:
    from modalviewer.core.demo_shapes import bumpy_plate

    app, win = bench_window()
    mesh = bumpy_plate(grid)
    out = {"vertices": mesh.n_vertices, "triangles": int(len(mesh.faces)), "k": k}
    t = time.perf_counter()
    win.set_mesh(mesh)
    win.viewport.render_now()
    app.processEvents()
    out["open_and_draw_s"] = round(time.perf_counter() - t, 2)
    statuses: list[str] = []
    win.viewer.events.status.connect(lambda text, *_: statuses.append(text))
    clock = EventLoopGaps()

    def compute(operator: str) -> dict:
        statuses.clear()
        stages: list[str] = []
        clock.reset()
        started = time.perf_counter()
        win.compute(operator, k=k, wait=False)  # a refusal is an error on the status line
        first_on_screen = None
        while win.viewer.jobs.busy:
            running = win.viewer.jobs.running
            if running is not None and (not stages or stages[-1] != running.stage):
                stages.append(running.stage)
            if first_on_screen is None and win.state.spectrum(operator) is not None:
                first_on_screen = time.perf_counter() - started
            app.processEvents()
            time.sleep(0.005)
        row = {
            "operator": operator,
            "on_screen_s": round(time.perf_counter() - started, 1),
            "first_on_screen_s": None if first_on_screen is None else round(first_on_screen, 1),
            "error": win.viewer.last_error,
            "status": list(dict.fromkeys(statuses)),
            "stages": list(dict.fromkeys(stages)),
            "longest_event_loop_gap_ms": _rounded(clock.longest_ms()),
            "child_peak_mb_so_far": round(_children_peak_mb()),
        }
        t = time.perf_counter()
        win.show_mode(10)
        win.viewport.render_now()
        app.processEvents()
        row["mode_redraw_s"] = round(time.perf_counter() - t, 2)
        win.export_screenshot(ROOT / "benchmarks" / "results" / f"million_{operator}.png")
        return row

    out["laplacian"] = compute("laplacian")
    # a pick shows the heat kernel distance from the vertex (the Laplacian's spectrum)
    win.state.set_display(distance_kind="hks")
    t = time.perf_counter()
    win.pick_vertex(mesh.n_vertices // 3)
    win.show_distance(display="threshold")
    win.viewport.render_now()
    app.processEvents()
    out["pick_and_distance_map_s"] = round(time.perf_counter() - t, 2)
    win.export_screenshot(ROOT / "benchmarks" / "results" / "million_laplacian_distance.png")
    clock.stop()
    win.close()
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--grid", type=int, default=1000)
    p.add_argument("-k", "--k", type=int, default=100)
    args = p.parse_args(argv)
    out = run(args.grid, args.k)
    for key, value in out.items():
        print(f"{key:24s} {value}")
    save_result("million", out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
