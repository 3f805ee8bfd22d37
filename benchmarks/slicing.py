"""Spectrum slicing against the single-shift solver, measured.

    python -m benchmarks.slicing --cases spot:loop:1 spot:loop:2 -k 300 --bands 2 3 4

Spectrum slicing (Vallet and Levy 2008) splits the wanted part of the spectrum into B
bands and runs one shift-invert iteration per band, each with a basis about B times
smaller, for B - 1 more factorisations (at shifts inside the spectrum: indefinite LDL^T
factors).  :mod:`benchmarks.sliced_solver` is such a solver, made of the library's parts
(the same Krylov iteration, refinement and Rayleigh-Ritz step), with PARDISO's inertia
to check each band.  Per case, each run in a fresh process with the compute process's
memory settings, alternating: the library's solver (``compute_spectrum``'s
``solve_lowest``) and the sliced solver for each B.  Recorded: seconds, peak memory,
operator columns, seconds per stage and per band, and the largest relative difference
of the non-zero eigenvalues to the single shift's.  Writes
``benchmarks/results/slicing.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.first_modes import _thousands, case_name, parse_case  # noqa: E402
from benchmarks.run import save_result  # noqa: E402

CHILD = """
import json, resource, sys, time
from modalviewer.core.memory import prepare_compute_process
prepare_compute_process()
import numpy as np
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.eigen import solve_lowest
from modalviewer.core.nullspace import null_space
from modalviewer.core.operators import operator_info
from benchmarks.first_modes import case_mesh
from benchmarks.sliced_solver import sliced_lowest
path, scheme, level, zup, operator, k, bands = sys.argv[1:8]
k, bands = int(k), int(bands)
mesh = case_mesh(path, scheme, int(level), zup == "1")
info = operator_info(operator)
K, mass = operator_matrices(mesh, info, 1.0, 1.0)
nulls = null_space(mesh, info, K, mass)
t = time.perf_counter()
if bands == 1:
    r = solve_lowest(K, mass, k, null_space=nulls.vectors)
    lam, stages, columns, per_band = r.eigenvalues, r.stage_seconds, r.operator_columns, []
else:
    lam, _, stages, columns, per_band = sliced_lowest(K, mass, k, bands, nulls.vectors)
seconds = time.perf_counter() - t
print(json.dumps({"vertices": mesh.n_vertices, "unknowns": K.shape[0], "seconds": seconds,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "stages": stages, "columns": columns, "bands": per_band,
                  "eigenvalues": [float(x) for x in lam]}))
"""


def run_child(case, operator: str, k: int, bands: int) -> dict:
    path, scheme, level, zup = case
    path = str(Path(path).resolve()) if Path(path).is_file() else path
    argv = [path, scheme, str(level), "1" if zup else "0", operator, str(k), str(bands)]
    child = subprocess.run(
        [sys.executable, "-c", CHILD, *argv], cwd=ROOT, capture_output=True, text=True
    )
    if child.returncode != 0:
        raise RuntimeError(child.stderr)
    return json.loads(child.stdout.strip().splitlines()[-1])


def largest_difference(lam: list, reference: list) -> float:
    """Largest relative difference of the non-zero eigenvalues."""
    top = max(abs(x) for x in reference)
    return max(
        (abs(a - b) / b for a, b in zip(lam, reference, strict=True) if b > 1e-8 * top),
        default=0.0,
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", type=parse_case, default=[parse_case("spot:loop:1")])
    parser.add_argument("--operator", default="shells")
    parser.add_argument("-k", type=int, default=300)
    parser.add_argument("--bands", nargs="+", type=int, default=[2, 3, 4])
    args = parser.parse_args(argv)
    rows = []
    for case in args.cases:
        single = run_child(case, args.operator, args.k, 1)
        sliced = {b: run_child(case, args.operator, args.k, b) for b in args.bands}
        for bands, run in [(1, single), *sliced.items()]:
            rows.append(
                {
                    "case": case_name(case),
                    "operator": args.operator,
                    "k": args.k,
                    "bands": bands,
                    **{key: value for key, value in run.items() if key != "bands"},
                    "per_band": run["bands"],
                    "share": run["seconds"] / single["seconds"],
                    "peak_share": run["peak_mb"] / single["peak_mb"],
                    "largest_eigenvalue_difference": largest_difference(
                        run["eigenvalues"], single["eigenvalues"]
                    ),
                }
            )
            print(json.dumps({k: v for k, v in rows[-1].items() if k != "eigenvalues"}))
    save_result("slicing", {"rows": rows})
    print(table({"rows": rows}))
    return 0


def table(data: dict) -> str:
    """The Markdown table of the results."""
    lines = [
        "| mesh | vertices | modes | bands | seconds | / single shift | peak / single shift "
        "| operator columns | solves | orthogonalisation, restarts, Ritz | factorisations "
        "| largest eigenvalue difference |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in data["rows"]:
        stages = r["stages"]
        basis = sum(stages.get(s, 0.0) for s in ("orthogonalisation", "restarts", "ritz"))
        solves = stages.get("solves", 0.0) + stages.get("refinement", 0.0)
        bands = "single shift" if r["bands"] == 1 else str(r["bands"])
        lines.append(
            f"| {r['case']} | {_thousands(r['vertices'])} | {r['k']} | {bands} | "
            f"{r['seconds']:.1f} s | {r['share']:.2f} | {r['peak_share']:.2f} | "
            f"{r['columns']} | {solves:.1f} s | {basis:.1f} s | "
            f"{stages.get('factorisation', 0.0):.1f} s | "
            f"{r['largest_eigenvalue_difference']:.0e} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
