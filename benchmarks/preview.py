"""Preview spectra beside the exact solve and Coarse-to-fine.

    python -m benchmarks.preview [--sizes 10k 50k 130k] [--operators laplacian shells] [--k 100]

For each benchmark mesh (those of ``benchmarks.run``) and operator, three ways to get k
modes, each in a fresh process (so its peak memory is its own):

- exact: ``compute_spectrum(mesh, op, k)``;
- preview: ``compute_spectrum(mesh, op, k, accuracy="preview")``;
- coarse-to-fine: decimate to a fifth of the vertices (as the viewer's option does,
  decimation timed too), compute there, carry the modes to the full mesh by nearest vertex.

Reported against the exact spectrum: wall time (assembly included), its ratio to the
exact time, the process's CPU time (less sensitive to other work on a shared machine),
the relative error of the lowest 50 non-zero eigenvalues (max and median), the Pearson
correlation of the multi-scale distance (heat kernel for the Laplacian, vibration for the
shells) from 20 random vertices (median and min), peak memory, and for the preview its
own estimated error beside the measured one.  Results go to
``benchmarks/results/preview.json`` and a Markdown table is printed.
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

from benchmarks.run import _in_child, make_mesh, peak_mb, save_result  # noqa: E402

N_VERTICES = 20
N_EIGENVALUES = 50


def _distances(spec, vertices) -> np.ndarray:
    import modalviewer as mv

    return np.stack([mv.multiscale_distance(spec, int(v)) for v in vertices])


def _method(size: str, operator: str, k: int, method: str) -> dict:
    """One method in this (fresh) process: time, eigenvalues, distances, peak memory."""
    import modalviewer as mv

    mesh = make_mesh(size)
    vertices = np.random.default_rng(0).integers(0, mesh.n_vertices, N_VERTICES)
    t0 = time.perf_counter()
    c0 = time.process_time()
    extra = {}
    if method == "coarse-to-fine":
        from modalviewer.coarsen import decimated_copy, transfer_spectrum

        coarse = decimated_copy(mesh)
        spec = transfer_spectrum(mv.compute_spectrum(coarse, operator, k=k), coarse, mesh)
        extra["coarse_vertices"] = coarse.n_vertices
    else:
        accuracy = "preview" if method == "preview" else "exact"
        spec = mv.compute_spectrum(mesh, operator, k=k, accuracy=accuracy)
    seconds = time.perf_counter() - t0
    cpu = time.process_time() - c0
    if spec.is_preview:
        info = spec.parameters["preview"]
        extra.update(
            samples=info["samples"],
            reduced_dimension=info["reduced_dimension"],
            stages=info["seconds_by_stage"],
            assembly_s=spec.parameters["seconds_assembly"],
            estimated_errors=info["estimated_errors"],
        )
    return {
        "method": method,
        "seconds": seconds,
        "cpu_seconds": cpu,
        "peak_mb": peak_mb(),
        "vertices": mesh.n_vertices,
        "eigenvalues": spec.eigenvalues.tolist(),
        "zero": spec.zero_mode_mask().tolist(),
        "distances": _distances(spec, vertices),
        **extra,
    }


def compare(exact: dict, other: dict) -> dict:
    """Errors of ``other`` against ``exact``."""
    lam = np.asarray(exact["eigenvalues"])
    nonzero = np.flatnonzero(~np.asarray(exact["zero"]))[:N_EIGENVALUES]
    approx = np.asarray(other["eigenvalues"])
    rel = (approx[nonzero] - lam[nonzero]) / lam[nonzero]
    corr = [
        float(np.corrcoef(a, b)[0, 1])
        for a, b in zip(exact["distances"], other["distances"], strict=True)
    ]
    row = {
        "seconds": other["seconds"],
        "time_ratio": other["seconds"] / exact["seconds"],
        "cpu_seconds": other["cpu_seconds"],
        "cpu_ratio": other["cpu_seconds"] / exact["cpu_seconds"],
        "eig_rel_error_max": float(np.max(np.abs(rel))),
        "eig_rel_error_median": float(np.median(np.abs(rel))),
        "eig_below_exact": int(np.sum(rel < -1e-8)),
        "distance_corr_median": float(np.median(corr)),
        "distance_corr_min": float(np.min(corr)),
        "peak_mb": other["peak_mb"],
    }
    if "estimated_errors" in other:
        est = np.asarray(other["estimated_errors"])[nonzero]
        row["estimated_error_max"] = float(est.max())
        row["estimated_error_median"] = float(np.median(est))
        ratio = est / np.maximum(np.abs(rel), 1e-12)
        row["estimate_over_error_median"] = float(np.median(ratio))
    for key in ("samples", "reduced_dimension", "stages", "assembly_s", "coarse_vertices"):
        if key in other:
            row[key] = other[key]
    return row


def run(sizes, operators, k, coarse=True) -> list[dict]:
    rows = []
    for size in sizes:
        for operator in operators:
            exact = _in_child(_method, size, operator, k, "exact")
            methods = ["preview"] + (["coarse-to-fine"] if coarse else [])
            row = {
                "mesh": size,
                "vertices": exact["vertices"],
                "operator": operator,
                "k": k,
                "exact_s": exact["seconds"],
                "exact_cpu_s": exact["cpu_seconds"],
                "exact_peak_mb": exact["peak_mb"],
            }
            for method in methods:
                row[method] = compare(exact, _in_child(_method, size, operator, k, method))
            rows.append(row)
            print(json.dumps(row), flush=True)
    return rows


def table(rows) -> str:
    head = (
        "| mesh | operator | method | time s | / exact | CPU s | eig. error max / median "
        "| estimated max | distance corr. median / min | peak MB |"
    )
    lines = [head, "|" + " --- |" * 10]
    for r in rows:
        lines.append(
            f"| {r['mesh']} | {r['operator']} | exact | {r['exact_s']:.1f} | 1 "
            f"| {r['exact_cpu_s']:.1f} | - | - | - "
            f"| {r['exact_peak_mb']:.0f} |"
        )
        for method in ("preview", "coarse-to-fine"):
            if method not in r:
                continue
            m = r[method]
            est = f"{m['estimated_error_max']:.1%}" if "estimated_error_max" in m else "-"
            lines.append(
                f"| {r['mesh']} | {r['operator']} | {method} | {m['seconds']:.1f} "
                f"| {m['time_ratio']:.2f} | {m['cpu_seconds']:.1f} "
                f"| {m['eig_rel_error_max']:.1%} / "
                f"{m['eig_rel_error_median']:.1%} | {est} | {m['distance_corr_median']:.3f} / "
                f"{m['distance_corr_min']:.3f} | {m['peak_mb']:.0f} |"
            )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", nargs="+", default=["10k", "50k", "130k"])
    p.add_argument("--operators", nargs="+", default=["laplacian", "shells"])
    p.add_argument("--k", type=int, default=100)
    p.add_argument("--no-coarse", action="store_true", help="leave out coarse-to-fine")
    p.add_argument("--name", default="preview", help="results file name (without .json)")
    args = p.parse_args(argv)
    rows = run(args.sizes, args.operators, args.k, not args.no_coarse)
    save_result(args.name, rows)
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
