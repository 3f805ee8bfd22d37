"""The eigensolver's time with numpy imported before modalviewer and after it.

    python -m benchmarks.import_order [--runs 3] [--k 100] [--label current] [--compare]

Each measurement runs in a fresh process on the 10k benchmark mesh (spot midpoint-
subdivided once, ~11.7k vertices): ``numpy_first`` imports numpy (and runs one BLAS
call) before ``import modalviewer``, ``modalviewer_first`` imports modalviewer first.
The thread settings are not in the environment of the children, so what counts is only
what modalviewer sets itself.  Results (the median of the runs, and every run) go to
benchmarks/results/import_order.json under ``--label``; earlier labels are kept, with the
load average of the machine before and after.  ``--compare`` alternates each run with
one without the run-time limit (``MODALVIEWER_SINGLE_BLAS_THREAD=0``, the environment
variables alone), so both see the same load; those rows have ``"limit": false``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "import_order.json"
ORDERS = ("numpy_first", "modalviewer_first")
THREAD_VARIABLES = ("KMP_BLOCKTIME", "OPENBLAS_THREAD_TIMEOUT", "MKL_DYNAMIC")


def child(order: str, operator: str, k: int) -> None:
    if order == "numpy_first":
        import numpy as np

        a = np.ones((200, 200))
        _ = a @ a  # OpenBLAS starts its threads here
    sys.path.insert(0, str(ROOT))
    import modalviewer as mv
    from benchmarks.run import make_mesh

    mesh = make_mesh("10k")
    spec = mv.compute_spectrum(mesh, operator, k=k)
    print(json.dumps({"seconds": spec.parameters["seconds_total"], "n": mesh.n_vertices}))


def measure(order: str, operator: str, k: int, limit: bool | None = None) -> dict:
    env = {k_: v for k_, v in os.environ.items() if k_ not in THREAD_VARIABLES}
    if limit is not None:
        env["MODALVIEWER_SINGLE_BLAS_THREAD"] = "1" if limit else "0"
    out = subprocess.run(
        [sys.executable, "-m", "benchmarks.import_order", "--child", order, operator, str(k)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--k", type=int, default=100)
    p.add_argument("--operators", nargs="+", default=["laplacian", "shells"])
    p.add_argument("--label", default="current")
    p.add_argument("--compare", action="store_true", help="also without the run-time limit")
    p.add_argument("--child", nargs=3, metavar=("ORDER", "OPERATOR", "K"))
    args = p.parse_args()
    if args.child:
        child(args.child[0], args.child[1], int(args.child[2]))
        return
    rows = []
    load_before = os.getloadavg()[0]
    limits = (True, False) if args.compare else (None,)
    for operator in args.operators:
        for order in ORDERS:
            runs = {lim: [] for lim in limits}
            for _ in range(args.runs):
                for lim in limits:
                    runs[lim].append(measure(order, operator, args.k, lim))
            for lim, found in runs.items():
                seconds = [r["seconds"] for r in found]
                row = {
                    "operator": operator,
                    "order": order,
                    "limit": lim is not False,
                    "k": args.k,
                    "n_vertices": found[0]["n"],
                    "median_seconds": round(statistics.median(seconds), 3),
                    "runs": [round(s, 3) for s in seconds],
                }
                rows.append(row)
                print(
                    f"{operator:10s} {order:18s} limit={row['limit']!s:5s} "
                    f"{row['median_seconds']:7.2f} s  {row['runs']}"
                )
    results = json.loads(RESULTS.read_text()) if RESULTS.exists() else {}
    results[args.label] = {
        "cpus": os.cpu_count(),
        "load_average": [round(load_before, 2), round(os.getloadavg()[0], 2)],
        "rows": rows,
    }
    RESULTS.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
