"""Time and peak memory of the exact solve against mesh size, 10k to 1M vertices, for
every operator, with the fitted growth exponents (the memory check's laws).

    python -m benchmarks.growth [--grids 100 180 320 580 1000] [--operators ...] [-k 100]

The meshes are the bumpy plate (:func:`modalviewer.core.demo_shapes.bumpy_plate`) on
n x n grids: 10k, 32k, 102k, 336k and 1M vertices by default.  Every (size, operator)
runs in a fresh process with the computation processes' memory settings, so
its peak resident memory is its own; mesh construction is not timed, assembly is.  A run
the memory check refuses (:func:`modalviewer.core.memory.memory_refusal`: more than
three quarters of this machine's memory expected) is recorded as refused with the
estimate, not started.  Growth exponents are least-squares fits of log(seconds) and
log(peak MB) against log(vertices) over the sizes from 100k on (below that, fixed costs
dominate).  The exact solves keep their factors in core (the children's memory limit
is the whole machine), so the laws are in-core laws.  Writes
``benchmarks/results/growth.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import _in_child, peak_mb, save_result  # noqa: E402

FIT_FROM = 100_000
"""The growth laws are fitted to the runs from this many vertices on; below it fixed
costs dominate."""


def _one(grid: int, operator: str, k: int) -> dict:
    import modalviewer as mv
    from modalviewer.core.demo_shapes import bumpy_plate

    mesh = bumpy_plate(grid)
    before = peak_mb()
    t = time.perf_counter()
    mv.compute_spectrum(mesh, operator, k)
    seconds = time.perf_counter() - t
    return {
        "grid": grid,
        "vertices": mesh.n_vertices,
        "operator": operator,
        "k": int(k),
        "seconds": round(seconds, 3),
        "peak_mb": round(peak_mb()),
        "mesh_mb": round(before),
    }


def _refusal(grid: int, operator: str, k: int) -> str | None:
    from modalviewer.core.memory import memory_refusal
    from modalviewer.core.operators import operator_info

    return memory_refusal(operator_info(operator), k, grid * grid)


def fit_growth(rows: list[dict], value: str) -> tuple[float, float] | None:
    """(value at 100k vertices, exponent): the least-squares line of log(value) against
    log(vertices / 100k) over the rows from :data:`FIT_FROM` vertices on (None with
    fewer than two)."""
    use = [r for r in rows if r.get(value) and r["vertices"] >= FIT_FROM]
    if len(use) < 2:
        return None
    x = np.log([r["vertices"] / 1e5 for r in use])
    y = np.log([r[value] for r in use])
    slope, intercept = np.polyfit(x, y, 1)
    return float(np.exp(intercept)), float(slope)


def main(argv=None) -> int:
    import os

    from modalviewer.core.memory import physical_memory_mb
    from modalviewer.core.operators import OPERATOR_NAMES

    # The laws are of solves with the factor in core (the memory check adds the factor's
    # out-of-core size where it goes out of core): the children may use all the memory.
    os.environ["MODALVIEWER_MEMORY_LIMIT_MB"] = str(round(physical_memory_mb() or 1e9))

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--grids", type=int, nargs="+", default=[100, 180, 320, 580, 1000])
    p.add_argument("--operators", nargs="+", default=list(OPERATOR_NAMES))
    p.add_argument("-k", type=int, default=100)
    p.add_argument("--name", default="growth", help="results file: benchmarks/results/NAME.json")
    p.add_argument(
        "--keep-others",
        action="store_true",
        help="keep the results file's rows of other grids or operators (re-measure some)",
    )
    p.add_argument(
        "--refit", action="store_true", help="only fit again the rows in the results file"
    )
    args = p.parse_args(argv)
    if args.refit:
        data = json.loads((ROOT / "benchmarks" / "results" / f"{args.name}.json").read_text())
        save_result(args.name, {**data, "fits": _fits(data["rows"])})
        return 0
    rows = []
    order = list(OPERATOR_NAMES)
    results = ROOT / "benchmarks" / "results" / f"{args.name}.json"
    if args.keep_others and results.is_file():  # rows of what is not run now stay
        rows = [
            r
            for r in json.loads(results.read_text())["rows"]
            if not (r["grid"] in args.grids and r["operator"] in args.operators)
        ]
    for grid in args.grids:
        for operator in args.operators:
            refused = _refusal(grid, operator, args.k)
            if refused:
                row = {
                    "grid": grid,
                    "vertices": grid * grid,
                    "operator": operator,
                    "k": args.k,
                    "refused": refused,
                }
            else:
                row = _in_child(_one, grid, operator, args.k)
            rows.append(row)
            print(row, flush=True)
            rows.sort(key=lambda r: (r["grid"], order.index(r["operator"])))
            save_result(args.name, {"k": args.k, "rows": rows, "fits": _fits(rows)})
    return 0


def _fits(rows: list[dict]) -> list[dict]:
    fits = []
    for operator in dict.fromkeys(r["operator"] for r in rows):
        sel = [r for r in rows if r["operator"] == operator]
        time_fit, memory_fit = fit_growth(sel, "seconds"), fit_growth(sel, "peak_mb")
        if time_fit and memory_fit:
            fits.append(
                {
                    "operator": operator,
                    "seconds_at_100k": round(time_fit[0], 3),
                    "time_exponent": round(time_fit[1], 3),
                    "peak_mb_at_100k": round(memory_fit[0], 1),
                    "memory_exponent": round(memory_fit[1], 3),
                }
            )
    return fits


if __name__ == "__main__":
    raise SystemExit(main())
