"""The 3D shells fast preview from a coarse copy against the smooth-space one and the
exact spectrum, on curved meshes with thin parts; each run in its own process.

    python -m benchmarks.coarse_start --cases spot:loop:3 hand:loop:2
    python -m benchmarks.coarse_start --cases /path/cow.obj:loop:3 -k 100

A case is ``asset:scheme:level`` as in :mod:`benchmarks.curved` (the asset a bundled
one's short name or a mesh file).  For each case: the exact spectrum, the fast
preview from the smooth space (``accuracy="fast preview"``) and the fast preview from a
coarse copy (:func:`modalviewer.coarsen.preview_copy`, its decimation timed with it);
the previews' lowest 50 non-zero eigenvalues are compared with the exact ones, and the
copy's own process's peak memory is recorded beside the computing process's.  Each
process computes with the compute processes' memory settings
(:func:`modalviewer.processes.memory.prepare_compute_process`).

``factor_stages_time_ratio`` is the share of the exact time that the coarse preview's
work with the fine operator takes: the exact run's assembly, the preview's factor, its
inverse-iteration step (one solve per carried mode and the Rayleigh-Ritz) and its
estimate (one solve per mode).  A preview that corrects any start with a factor of the
fine operator and estimates each mode's error with it needs at least these, whatever
the start costs.  Writes ``benchmarks/results/coarse_start.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.curved import case_name, case_path, parse_case  # noqa: E402
from benchmarks.run import add_keep_others, kept_rows, save_result  # noqa: E402

CHILD = """
import json, resource, sys, time
from modalviewer.processes.memory import prepare_compute_process
prepare_compute_process()
import modalviewer as mv
from modalviewer.coarsen import preview_copy
from benchmarks.curved import case_mesh
path, scheme, start = sys.argv[1], sys.argv[2], sys.argv[4]
level, k = int(sys.argv[3]), int(sys.argv[5])
mesh = case_mesh(path, scheme, level)
t = time.perf_counter()
copy = preview_copy(mesh, k) if start == "coarse" else None
copy_seconds = time.perf_counter() - t
accuracy = "exact" if start == "exact" else "fast preview"
spec = mv.compute_spectrum(mesh, "shells", k, accuracy=accuracy, coarse=copy)
seconds = time.perf_counter() - t
info = spec.parameters.get("preview", {})
print(json.dumps({"vertices": mesh.n_vertices, "seconds": seconds,
                  "copy_seconds": copy_seconds,
                  "coarse_vertices": info.get("coarse_start", {}).get("coarse_vertices", 0),
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                  "copy_peak_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
                  "eigenvalues": [float(x) for x in spec.eigenvalues[~spec.zero_mode_mask()]],
                  "estimated_errors": info.get("estimated_errors", [])[6:],
                  "assembly_seconds": spec.parameters.get("seconds_assembly", 0.0),
                  "start_seconds": info.get("coarse_start", {}).get("seconds", {}),
                  "stage_seconds": info.get("seconds_by_stage", {})}))
"""


def run(case, start: str, k: int) -> dict:
    mesh, scheme, level = case
    path = case_path(mesh)
    out = subprocess.run(
        [sys.executable, "-c", CHILD, path, scheme, str(level), start, str(k)],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def _errors(preview: dict, exact: dict, m: int = 50) -> tuple[float, float]:
    """(largest relative error, largest estimate) of the lowest m non-zero modes."""
    lam, ref = preview["eigenvalues"][:m], exact["eigenvalues"][:m]
    error = max(abs(a - b) / b for a, b in zip(lam, ref, strict=True))
    return error, max(preview["estimated_errors"][:m], default=0.0)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cases", type=parse_case, nargs="+", required=True)
    p.add_argument("-k", type=int, default=100)
    add_keep_others(p, "other cases")
    args = p.parse_args(argv)
    names = {case_name(case) for case in args.cases}
    rows = kept_rows("coarse_start", args.keep_others, lambda r: r["mesh"] in names)
    for case in args.cases:
        exact = run(case, "exact", args.k)
        smooth = run(case, "smooth", args.k)
        coarse = run(case, "coarse", args.k)
        row = {"mesh": case_name(case), "vertices": exact["vertices"], "k": args.k}
        row["exact_seconds"] = round(exact["seconds"], 2)
        row["exact_peak_mb"] = round(exact["peak_mb"])
        for name, result in (("smooth", smooth), ("coarse", coarse)):
            error, estimate = _errors(result, exact)
            row[f"{name}_seconds"] = round(result["seconds"], 2)
            row[f"{name}_time_ratio"] = round(result["seconds"] / exact["seconds"], 3)
            row[f"{name}_peak_mb"] = round(result["peak_mb"])
            row[f"{name}_largest_error_lowest_50"] = round(error, 5)
            row[f"{name}_estimated_error_lowest_50"] = round(estimate, 5)
        row["coarse_copy_seconds"] = round(coarse["copy_seconds"], 2)
        # the copy's own process (modalviewer.processes.copy_main) ends before the
        # spectrum's solve begins: its peak is not alive beside the compute peak
        row["coarse_copy_peak_mb"] = round(coarse["copy_peak_mb"])
        row["coarse_vertices"] = coarse["coarse_vertices"]
        start, stages = coarse["start_seconds"], coarse["stage_seconds"]
        if "factor" in start:  # the coarse start ran (no fallback to the smooth space)
            estimate = stages.get("estimate", 0.0)
            fine = (
                exact["assembly_seconds"] + start["factor"] + start["inverse_iteration"] + estimate
            )
            row["coarse_stage_seconds"] = {**start, "estimate": estimate}
            row["factor_stages_time_ratio"] = round(fine / exact["seconds"], 3)
        rows.append(row)
        print(json.dumps(row), flush=True)
        save_result("coarse_start", {"rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
