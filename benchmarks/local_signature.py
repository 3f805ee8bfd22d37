"""Signatures at a few vertices: Lemma 2 (``local_signature``) against the eigen route.

    python -m benchmarks.local_signature [--vertices 5] [--k 100 300]

For each mesh and operator this measures, in one process:

- ``eigen_k``: ``compute_spectrum(mesh, operator, k)`` plus ``signature`` at the
  vertices, for each k of ``--k`` (the baseline: what the viewer does today);
- ``local_small``: ``local_signature`` alone (no spectrum) at the two small scales
  ``t1 / 10`` and ``t1`` (``t1`` the smallest default scale of the largest-k spectrum);
- ``hybrid``: ``compute_spectrum(k = smallest of --k)`` plus ``local_signature(...,
  spectrum=...)`` at every default scale and ``t1 / 10``: the sum over all modes;
- the truncation error of each eigen route against the hybrid (which has none), at
  ``t1`` and ``t1 / 10``.

Ratios are local / eigen in the same run.  Results: ``benchmarks/results/local_signature.json``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import modalviewer as mv
from scripts.make_assets import machined_part

ASSETS = Path(__file__).resolve().parents[1] / "assets"
RESULTS = Path(__file__).resolve().parent / "results" / "local_signature.json"


def _meshes():
    yield "machined part (CAD, sharp edges)", machined_part()
    yield "hand (organic, thin fingers)", mv.load_mesh(ASSETS / "demo_hand.obj")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=5)
    parser.add_argument("--k", type=int, nargs="+", default=[100, 300])
    parser.add_argument(
        "--operators", nargs="+", default=["laplacian", "modified_dirichlet", "shells"]
    )
    args = parser.parse_args(argv)
    rows = []
    for name, mesh in _meshes():
        rng = np.random.default_rng(0)
        vertices = np.sort(rng.choice(mesh.n_vertices, args.vertices, replace=False))
        for operator in args.operators:
            row = {"mesh": name, "n_vertices": mesh.n_vertices, "operator": operator}
            eigen = {}
            for k in sorted(args.k):
                started = time.perf_counter()
                spec = mv.compute_spectrum(mesh, operator, k=k)
                eigen[k] = (spec, time.perf_counter() - started)
            largest = eigen[max(args.k)][0]
            times = mv.default_times(largest)
            times = np.concatenate([[times[0] / 10], times])
            started = time.perf_counter()
            mv.local_signature(mesh, operator, vertices, times[:2])
            row["local_small_seconds"] = time.perf_counter() - started
            smallest_spec, smallest_seconds = eigen[min(args.k)]
            started = time.perf_counter()
            local = mv.local_signature(mesh, operator, vertices, times, spectrum=smallest_spec)
            row["hybrid_seconds"] = smallest_seconds + time.perf_counter() - started
            for k, (spec, seconds) in eigen.items():
                started = time.perf_counter()
                _, values = mv.signature(spec, times, vertices=vertices)
                seconds += time.perf_counter() - started
                missing = 1 - values / local
                row[f"eigen_{k}_seconds"] = seconds
                row[f"ratio_local_small_to_eigen_{k}"] = row["local_small_seconds"] / seconds
                row[f"ratio_hybrid_to_eigen_{k}"] = row["hybrid_seconds"] / seconds
                row[f"eigen_{k}_missing_at_t1"] = float(np.max(missing[:, 1]))
                row[f"eigen_{k}_missing_at_t1_over_10"] = float(np.max(missing[:, 0]))
            row["vertices"] = vertices.tolist()
            row["t1"], row["t2"] = float(times[1]), float(times[-1])
            rows.append(row)
            print(json.dumps(row))
    RESULTS.write_text(json.dumps({"rows": rows, "vertices": args.vertices}, indent=1) + "\n")
    print(f"wrote {RESULTS}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
