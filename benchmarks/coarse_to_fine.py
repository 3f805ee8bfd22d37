"""Coarse-to-fine (paper Section 7, Fig. 9) against the full computation.

    python -m benchmarks.coarse_to_fine [--size 50k] [--operator shells] [--k 100]

Decimates the benchmark mesh to a fifth of its vertices (VTK progressive decimation with
topology preserved, as the viewer's Coarse-to-fine option does), computes the spectrum
there, carries it to the full mesh by nearest vertex and compares with the full
computation: time of both, relative error of the eigenvalues (non-zero modes), and the
Pearson correlation of the multi-scale distance from 20 random vertices (the distance the
viewer shows).  Results go to
``benchmarks/results/coarse_to_fine_<size>.json``.
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

import modalviewer as mv  # noqa: E402
from benchmarks.run import make_mesh, save_result  # noqa: E402
from modalviewer.coarsen import decimated_copy, transfer_spectrum  # noqa: E402


def run(size: str, operator: str, k: int) -> dict:
    fine = make_mesh(size)
    coarse = decimated_copy(fine)
    t0 = time.perf_counter()
    full = mv.compute_spectrum(fine, operator, k=k)
    t_full = time.perf_counter() - t0
    t0 = time.perf_counter()
    spec_coarse = mv.compute_spectrum(coarse, operator, k=k)
    moved = transfer_spectrum(spec_coarse, coarse, fine)
    t_coarse = time.perf_counter() - t0
    nonzero = ~full.zero_mode_mask()
    rel = np.abs(moved.eigenvalues[nonzero] - full.eigenvalues[nonzero]) / np.abs(
        full.eigenvalues[nonzero]
    )
    rng = np.random.default_rng(0)
    corr = []
    for v in rng.integers(0, fine.n_vertices, 20):
        a = mv.multiscale_distance(full, int(v))
        b = mv.multiscale_distance(moved, int(v))
        corr.append(float(np.corrcoef(a, b)[0, 1]))
    return {
        "mesh": size,
        "vertices": fine.n_vertices,
        "coarse_vertices": coarse.n_vertices,
        "operator": operator,
        "k": k,
        "full_s": t_full,
        "coarse_s": t_coarse,
        "eigenvalue_rel_error_median": float(np.median(rel)),
        "eigenvalue_rel_error_first10": [float(x) for x in rel[:10]],
        "distance_correlation_median": float(np.median(corr)),
        "distance_correlation_min": float(np.min(corr)),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", default="50k", choices=["10k", "50k", "130k"])
    p.add_argument("--operator", default="shells", choices=list(mv.OPERATORS))
    p.add_argument("--k", type=int, default=100)
    args = p.parse_args(argv)
    result = run(args.size, args.operator, args.k)
    save_result(f"coarse_to_fine_{args.size}", result)
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
