"""Peak memory and time of big exact solves, with the factor in core and out of core.

    python -m benchmarks.memory --mesh path/to/cheburashka.obj --level 3 -k 300
    python -m benchmarks.memory --mesh hand --level 2 --limits none 3000

A mesh is a bundled asset name (``spot``, ``hand``, ``part``) or an OBJ/PLY path,
Loop-subdivided ``level`` times, or ``plate:N``, the bumpy plate on an N x N grid.  Each
limit (``none``: the default, :func:`modalviewer.core.memory.memory_limit_mb`; or
megabytes, passed as
``MODALVIEWER_MEMORY_LIMIT_MB``) runs ``compute_spectrum(mesh, operator, k)`` in a fresh
process with the computation processes' memory settings
(:func:`modalviewer.core.memory.prepare_compute_process`), so its peak resident
memory is its own.  After the peak is read the child checks the result: the largest
relative residual and the largest deviation of ``X^T M X`` from the identity (a block of
columns at a time, so the check adds no (N, k) array).  Each row keeps its eigenvalues;
the rows of one run are compared with its first row's, or all with a stored run of the
same operator (``--compare-with LABEL``, any k: over the modes both have).  Rows go to
``benchmarks/results/memory.json`` (rows of other meshes, operators or k are kept).

    python -m benchmarks.memory --mesh plate:1000 -k 300
    python -m benchmarks.memory --mesh plate:1000 -k 100 --limits 100000 \\
        --label "plate 1000 x 1000, in core" --compare-with "plate 1000 x 1000"
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.run import save_result  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results" / "memory.json"

CHILD = """
import json, resource, sys, time
import numpy as np
from modalviewer.core.memory import prepare_compute_process
prepare_compute_process()
import modalviewer as mv
mesh_arg, level, operator, k = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
if mesh_arg.startswith("plate:"):
    from modalviewer.core.demo_shapes import bumpy_plate
    mesh = bumpy_plate(int(mesh_arg.split(":")[1]))
else:
    from benchmarks.curved import ASSETS, case_mesh
    mesh = case_mesh(ASSETS.get(mesh_arg, mesh_arg), "loop", level)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
t = time.perf_counter()
spec = mv.compute_spectrum(mesh, operator, k)
seconds = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
X = spec.modes.reshape(-1, spec.modes.shape[-1])
mass = np.repeat(spec.mass, X.shape[0] // spec.mass.shape[0])
worst = 0.0
for start in range(0, X.shape[1], 32):
    cols = slice(start, start + 32)
    G = X.T @ (mass[:, None] * X[:, cols])
    E = np.zeros_like(G)
    E[start : start + G.shape[1]] = np.eye(G.shape[1])[: G.shape[0] - start]
    worst = max(worst, float(np.abs(G - E).max()))
p = spec.parameters
print(json.dumps({"vertices": mesh.n_vertices, "unknowns": int(X.shape[0]), "seconds": seconds,
                  "peak_mb": peak, "mesh_mb": before, "method": p.get("method"),
                  "factor_mb": p.get("factor_mb"),
                  "factor_out_of_core": p.get("factor_out_of_core"),
                  "basis_float32": p.get("basis_float32"),
                  "seconds_by_stage": p.get("seconds_by_stage"),
                  "max_residual": float(spec.residuals.max()), "mass_orthonormality": worst,
                  "eigenvalues": [float(x) for x in spec.eigenvalues]}))
"""


def relative_differences(lam: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Relative differences of the eigenvalues both arrays have (zero modes relative to
    1e-12 of the largest reference eigenvalue)."""
    m = min(lam.shape[0], reference.shape[0])
    scale = np.maximum(np.abs(reference[:m]), 1e-12 * np.abs(reference[:m]).max())
    return np.abs(lam[:m] - reference[:m]) / scale


def run(mesh: str, level: int, operator: str, k: int, limit: str) -> dict:
    env = dict(os.environ)
    env.pop("MODALVIEWER_MEMORY_LIMIT_MB", None)
    if limit != "none":
        env["MODALVIEWER_MEMORY_LIMIT_MB"] = limit
    out = subprocess.run(
        [sys.executable, "-c", CHILD, mesh, str(level), operator, str(k)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
    )
    if out.returncode != 0:
        raise RuntimeError(f"the child failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", default="hand", help="asset name or mesh file")
    parser.add_argument("--level", type=int, default=2, help="Loop subdivisions")
    parser.add_argument("--operator", default="shells")
    parser.add_argument("-k", type=int, default=300)
    parser.add_argument("--limits", nargs="+", default=["none"], help="'none' or MB")
    parser.add_argument("--label", default=None, help="the mesh's name in the results")
    parser.add_argument(
        "--compare-with", default=None, help="a stored run's label: compare with its eigenvalues"
    )
    args = parser.parse_args(argv)
    if args.mesh.startswith("plate:"):
        grid = args.mesh.split(":")[1]
        label = args.label or f"plate {grid} x {grid}"
    else:
        label = args.label or f"{Path(args.mesh).stem} Loop x{args.level}"
    old = json.loads(RESULTS.read_text())["rows"] if RESULTS.exists() else []
    rows = [r for r in old if (r["mesh"], r["operator"], r["k"]) != (label, args.operator, args.k)]
    reference, compared_with = None, None
    if args.compare_with:
        stored = [
            r
            for r in old
            if (r["mesh"], r["operator"]) == (args.compare_with, args.operator)
            and "eigenvalues" in r
        ]
        if not stored:
            parser.error(f"no stored {args.operator} run of {args.compare_with!r} with eigenvalues")
        reference, compared_with = np.array(stored[0]["eigenvalues"]), args.compare_with
    for limit in args.limits:
        row = run(args.mesh, args.level, args.operator, args.k, limit)
        lam = np.array(row["eigenvalues"])
        if reference is None:
            reference = lam
            row["largest_relative_difference"] = 0.0
        else:
            difference = relative_differences(lam, reference)
            row["largest_relative_difference"] = float(np.max(difference))
            row["compared_with"] = compared_with or f"{label}, limit {args.limits[0]}"
        row.update(mesh=label, operator=args.operator, k=args.k, limit_mb=limit)
        print(json.dumps({key: row[key] for key in ("mesh", "limit_mb", "seconds", "peak_mb",
                                                    "factor_out_of_core", "basis_float32",
                                                    "max_residual",
                                                    "largest_relative_difference")}))  # fmt: skip
        rows.append(row)
        save_result("memory", {"rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
