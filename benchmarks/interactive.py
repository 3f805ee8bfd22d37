"""Interactive costs of the real viewer window (off-screen) on a big mesh.

    python -m benchmarks.interactive [--size 130k] [--operator shells] [--k 100] [--desktop]

Drives ``modalviewer.gui.MainWindow`` as a user would and measures, separately, the
application's own work up to the render request and the draw itself (software OpenGL on
machines without a GPU): computing a spectrum while a 10 ms timer watches the event loop
(longest gap), cancelling a computation, reopening the cached spectrum, switching modes
with isolines, one animation frame, picking a vertex to a distance map (first pick builds
the signature table), one threshold-slider step.  Results go to
``benchmarks/results/interactive_<size>_<operator>[_desktop].json``; a Markdown table is
printed.  ``--desktop`` measures the desktop view (pyvistaqt's QtInteractor) instead, on
the X server in ``$DISPLAY`` with ``QT_QPA_PLATFORM=xcb`` (Xvfb will do).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import make_mesh, save_result  # noqa: E402
from modalviewer.core.cache import SpectrumCache  # noqa: E402
from modalviewer.core.operators import OPERATOR_INFO  # noqa: E402

KIND = {name: info.distance_kind for name, info in OPERATOR_INFO.items() if info.distance_kind}


def _stats(values) -> dict:
    a = 1e3 * np.asarray(values, dtype=float)
    return {"median_ms": float(np.median(a)), "max_ms": float(a.max()), "n": int(a.size)}


def run(size: str, operator: str, k: int, desktop: bool = False) -> dict:
    from qtpy import QtCore, QtWidgets

    from modalviewer.gui import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    cache_dir = tempfile.mkdtemp(prefix="modalviewer-bench-")
    win = MainWindow(
        force_offscreen=None if desktop else True, cache=SpectrumCache(Path(cache_dir))
    )
    win.resize(1280, 900)
    win.show()
    app.processEvents()
    mesh = make_mesh(size)
    win.set_mesh(mesh)
    win.viewport.render_now()  # the first draw of a new mesh is slow in software
    app.processEvents()
    out = {"mesh": size, "vertices": mesh.n_vertices, "operator": operator, "k": k}
    out["view"] = type(win.viewport).__name__

    # computing while a timer watches the event loop
    gaps, ends, last = [], [], [time.perf_counter()]

    def tick():
        now = time.perf_counter()
        gaps.append(now - last[0])
        ends.append(now)
        last[0] = now

    timer = QtCore.QTimer()
    timer.setInterval(10)
    timer.timeout.connect(tick)
    timer.start()
    started = time.perf_counter()
    win.compute(operator, k=k, wait=True)
    out["compute_s"] = time.perf_counter() - started
    timer.stop()
    worst = int(np.argmax(gaps))
    out["longest_event_loop_gap_ms"] = 1e3 * gaps[worst]
    # where it happened: seconds before the result was shown (0 = at its arrival)
    out["longest_gap_s_before_end"] = started + out["compute_s"] - ends[worst]

    # cancel: a different k is not cached; cancel in the middle of the work
    win.compute(operator, k=k + 1, wait=False)
    cancelled_job = win.running_job
    deadline = time.perf_counter() + min(3.0, 0.4 * out["compute_s"])
    while time.perf_counter() < deadline:
        app.processEvents()
        time.sleep(0.01)
    started = time.perf_counter()
    win.cancel_computation()
    while win.busy and time.perf_counter() - started < 30:
        app.processEvents()
        time.sleep(0.002)
    out["cancel_s"] = time.perf_counter() - started
    out["cancelled_while_running"] = cancelled_job is not None and (
        cancelled_job.status == "cancelled"
    )

    # reopening the cached spectrum (as a restart of the viewer would)
    win.set_mesh(mesh)  # drops the spectra in memory; the disk cache keeps them
    started = time.perf_counter()
    win.compute(operator, k=k, wait=True)
    out["cached_reopen_s"] = time.perf_counter() - started
    # the signature table for picks is built in the same job, before it reports
    out["table_ready_after_reopen_s"] = out["cached_reopen_s"]

    # mode switches with isolines: the app's work, then the draw
    app_t, draw_t = [], []
    for j in range(6, 16):
        t0 = time.perf_counter()
        win.show_mode(j)
        app_t.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        win.viewport.render_now()
        draw_t.append(time.perf_counter() - t0)
    out["mode_switch"] = _stats(app_t)
    out["draw"] = _stats(draw_t)

    win.show_mode(8)
    frames = [win.animation_frame(phase) for phase in np.linspace(0, 6.0, 60)]
    out["animation_frame"] = _stats(frames)

    rng = np.random.default_rng(0)
    kind = KIND[operator]
    win.show_distance(kind, display="threshold", share=0.2)
    picks = []
    for v in rng.integers(0, mesh.n_vertices, 11):
        t0 = time.perf_counter()
        win.pick_vertex(int(v))
        picks.append(time.perf_counter() - t0)
    out["first_pick_with_table_ms"] = 1e3 * picks[0]
    out["pick_to_distance_map"] = _stats(picks[1:])
    steps = [win.set_threshold(f) for f in np.linspace(0.05, 0.6, 40)]
    out["threshold_step"] = _stats(steps)
    win.close()
    return out


def table(r: dict) -> str:
    rows = [
        ("compute (s)", f"{r['compute_s']:.1f}"),
        ("longest event-loop gap while computing (ms)", f"{r['longest_event_loop_gap_ms']:.0f}"),
        ("cancel to stopped (s)", f"{r['cancel_s']:.2f}"),
        ("reopen cached spectrum (s)", f"{r['cached_reopen_s']:.2f}"),
        ("signature table ready after reopening (s)", f"{r['table_ready_after_reopen_s']:.2f}"),
        ("mode switch with isolines, app (ms, median / max)", "{median_ms:.1f} / {max_ms:.1f}"),
        ("draw (ms, median / max)", "{median_ms:.0f} / {max_ms:.0f}"),
        ("animation frame, app (ms)", "{median_ms:.2f} / {max_ms:.2f}"),
        ("first pick (ms)", f"{r['first_pick_with_table_ms']:.0f}"),
        ("pick to distance map, app (ms)", "{median_ms:.1f} / {max_ms:.1f}"),
        ("threshold step, app (ms)", "{median_ms:.2f} / {max_ms:.2f}"),
    ]
    keys = {
        "mode switch with isolines, app (ms, median / max)": "mode_switch",
        "draw (ms, median / max)": "draw",
        "animation frame, app (ms)": "animation_frame",
        "pick to distance map, app (ms)": "pick_to_distance_map",
        "threshold step, app (ms)": "threshold_step",
    }
    lines = [
        f"{r['mesh']} ({r['vertices']} vertices), {r['operator']}, k = {r['k']}",
        "",
        "| measure | value |",
        "| --- | --- |",
    ]
    for name, value in rows:
        if name in keys:
            value = value.format(**r[keys[name]])
        lines.append(f"| {name} | {value} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", default="130k", choices=["10k", "50k", "130k"])
    p.add_argument("--operator", default="shells", choices=sorted(KIND))
    p.add_argument("--k", type=int, default=100)
    p.add_argument(
        "--desktop",
        action="store_true",
        help="the desktop view (pyvistaqt's QtInteractor) on $DISPLAY, with "
        "QT_QPA_PLATFORM=xcb, instead of the off-screen view",
    )
    args = p.parse_args(argv)
    result = run(args.size, args.operator, args.k, args.desktop)
    suffix = "_desktop" if args.desktop else ""
    save_result(f"interactive_{args.size}_{args.operator}{suffix}", result)
    print(table(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
