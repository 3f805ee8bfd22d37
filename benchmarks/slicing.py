"""What spectrum slicing could buy: a bound from the single-shift solver's own stages.

    python -m benchmarks.slicing --cases spot:loop:1 path/to/cheburashka.obj:loop:2 -k 300

Spectrum slicing (Vallet and Levy 2008) splits the wanted part of the spectrum into B
bands and runs one shift-invert iteration per band, each with a basis about B times
smaller.  It trades B - 1 more factorisations (at shifts inside the spectrum, so of an
indefinite matrix: an LDL^T factor, at least as costly as the Cholesky factor of the
single shift) for a smaller basis.  From one run of the single-shift solver per case (in
a fresh process, with the compute process's memory settings) this benchmark records where
the time went (``EigenResult.stage_seconds``) and bounds the sliced solve from below:

- every band factors once: ``B * factorisation`` (the Cholesky time as the bound);
- the operator columns are at least those of the single shift: the same ``solves``;
- the stages whose cost grows with the basis's size (``orthogonalisation``,
  ``restarts``, ``ritz``) shrink at best by B;
- the rest (assembly, refinement, Rayleigh-Ritz, residuals, copies) is unchanged.

Memory, likewise: the factor, the k modes found so far and a basis B times smaller.
Writes ``benchmarks/results/slicing.json``.
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
import modalviewer as mv
from benchmarks.first_modes import case_mesh
path, scheme, level, zup, operator, k = sys.argv[1:7]
mesh = case_mesh(path, scheme, int(level), zup == "1")
t = time.perf_counter()
spec = mv.compute_spectrum(mesh, operator, int(k))
seconds = time.perf_counter() - t
p = spec.parameters
print(json.dumps({"vertices": mesh.n_vertices, "seconds": seconds,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "stages": p["seconds_by_stage"], "assembly": p["seconds_assembly"],
                  "factor_mb": p["factor_mb"], "columns": p["operator_columns"],
                  "unknowns": spec.modes.size // spec.k}))
"""

BASIS_STAGES = ("orthogonalisation", "restarts", "ritz")


def bound(run: dict, k: int, bands: int) -> dict:
    """The lower bound of a sliced solve's time and memory with ``bands`` bands."""
    stages = run["stages"]
    factor = stages.get("factorisation", 0.0)
    basis = sum(stages.get(s, 0.0) for s in BASIS_STAGES)
    rest = run["seconds"] - factor - basis
    seconds = bands * factor + basis / bands + rest
    n = run["unknowns"]
    modes_mb = 8.0 * n * k / 2**20
    return {"bands": bands, "seconds": seconds, "modes_mb": modes_mb}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", type=parse_case, default=[parse_case("spot:loop:1")])
    parser.add_argument("--operator", default="shells")
    parser.add_argument("-k", type=int, default=300)
    args = parser.parse_args(argv)
    rows = []
    for case in args.cases:
        path, scheme, level, zup = case
        path = str(Path(path).resolve()) if Path(path).is_file() else path
        argv_child = [path, scheme, str(level), "1" if zup else "0", args.operator, str(args.k)]
        child = subprocess.run(
            [sys.executable, "-c", CHILD, *argv_child], cwd=ROOT, capture_output=True, text=True
        )
        if child.returncode != 0:
            raise RuntimeError(child.stderr)
        run = json.loads(child.stdout.strip().splitlines()[-1])
        bounds = [bound(run, args.k, b) for b in (2, 3, 4, 6, 8)]
        best = min(bounds, key=lambda b: b["seconds"])
        rows.append(
            {
                "case": case_name(case),
                "operator": args.operator,
                "k": args.k,
                **run,
                "bounds": bounds,
                "best_bound_share": best["seconds"] / run["seconds"],
                "best_bands": best["bands"],
            }  # fmt: skip
        )
        print(json.dumps(rows[-1]), flush=True)
    save_result("slicing", {"rows": rows})
    print(table({"rows": rows}))
    return 0


def table(data: dict) -> str:
    """The Markdown table of the results."""
    lines = [
        "| mesh | vertices | modes | single shift | factorisation | orthogonalisation, "
        "restarts, Ritz | sliced, at best | bands | share |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in data["rows"]:
        basis = sum(r["stages"].get(s, 0.0) for s in BASIS_STAGES)
        best = next(b for b in r["bounds"] if b["bands"] == r["best_bands"])
        lines.append(
            f"| {r['case']} | {_thousands(r['vertices'])} | {r['k']} | {r['seconds']:.1f} s | "
            f"{r['stages'].get('factorisation', 0.0):.1f} s | {basis:.1f} s | "
            f"{best['seconds']:.1f} s | {r['best_bands']} | {r['best_bound_share']:.2f} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
