"""Timings of modalviewer against a plain-scipy baseline on the same matrices.

    python -m benchmarks.run [--sizes 10k 50k 130k] [--k 300] [--operators laplacian shells]
                             [--few 12 50] [--output latest]

Meshes (reproducible): spot subdivided once (~11.7k vertices) and twice (~47k), and the
bumpy plate on a 360 x 360 grid (~130k).  For each mesh and operator: Hessian/matrix
assembly, the eigenproblem for k modes (modalviewer's solver and the baseline
``eigsh(K, k, M=Mass, sigma=s)`` with scipy's default LU), the signature at all
vertices, the ratio, the largest relative eigenvalue difference (non-zero modes) and peak
memory (RSS high-water mark of the process that ran it: every measurement runs in a fresh
process), and where the solver's time went (factorisation, solves, orthogonalisation,
restarts, projected eigenproblems, refinement; ``EigenResult.stage_seconds``).  The
solver gets the operator's exactly known null space, as ``compute_spectrum`` does.
``--few`` adds rows for few modes (the Discrete Shells on the largest mesh, no baseline)
and a third table of their times against the k-mode row of the same run.  Results go to
benchmarks/results/<output>.json and the Markdown tables are printed.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import modalviewer as mv  # noqa: E402
from modalviewer.core.assembly import operator_matrices  # noqa: E402
from modalviewer.core.demo_shapes import bumpy_plate  # noqa: E402
from modalviewer.core.eigen import solve_lowest  # noqa: E402
from modalviewer.core.memory import prepare_compute_process  # noqa: E402
from modalviewer.core.nullspace import null_space  # noqa: E402
from modalviewer.core.operators import operator_info  # noqa: E402


def make_mesh(size: str) -> mv.Mesh:
    import trimesh

    """The benchmark meshes: "10k" / "50k" spot midpoint-subdivided once / twice (the
    original triangles stay flat), "50k-smooth" spot Loop-subdivided twice (a smooth
    surface), "130k" the bumpy plate."""
    if size == "130k":
        return bumpy_plate(360)
    spot = mv.load_mesh(ROOT / "assets" / "spot.obj")
    v, f = spot.vertices, spot.faces
    if size == "50k-smooth":
        v, f = trimesh.remesh.subdivide_loop(v, f, iterations=2)
        return mv.Mesh(v, f)
    for _ in range({"10k": 1, "50k": 2}[size]):
        v, f = trimesh.remesh.subdivide(v, f)
    mesh = mv.repair_mesh(v, f)
    return mv.Mesh(mesh.vertices, mesh.faces)


def save_result(name: str, data) -> None:
    """Write ``data`` as ``benchmarks/results/<name>.json``."""
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")


def add_keep_others(parser, what: str) -> None:
    """The ``--keep-others`` option of a benchmark that re-measures some of its rows:
    ``what`` says which rows are kept (e.g. "other cases or operators")."""
    parser.add_argument(
        "--keep-others",
        action="store_true",
        help=f"keep the results file's rows of {what} (re-measure some)",
    )


def kept_rows(name: str, keep: bool, measured_now) -> list[dict]:
    """The rows of ``benchmarks/results/<name>.json`` (a list of rows, or ``{"rows":
    [...]}``) for which ``measured_now(row)`` is False, where ``keep`` is set (the
    ``--keep-others`` option) and the file exists; otherwise none."""
    path = ROOT / "benchmarks" / "results" / f"{name}.json"
    if not keep or not path.is_file():
        return []
    data = json.loads(path.read_text())
    rows = data["rows"] if isinstance(data, dict) else data
    return [row for row in rows if not measured_now(row)]


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def baseline(K, mass, k, shift):
    """Plain scipy: eigsh in shift-invert mode with its default (LU) factorisation."""
    lam, _ = spla.eigsh(K.tocsc(), k=k, M=sp.diags(mass).tocsc(), sigma=shift, which="LM")
    return np.sort(lam)


def _ours(size: str, operator: str, k: int) -> dict:
    """One row of the project's timings, in a fresh process (so peak memory is its own)."""
    mesh = make_mesh(size)
    t0 = time.perf_counter()
    K, mass = operator_matrices(mesh, operator)
    t_assembly = time.perf_counter() - t0
    t0 = time.perf_counter()
    nulls = null_space(mesh, operator, K, mass)
    result = solve_lowest(K, mass, k, null_space=nulls.vectors)
    t_eigen = time.perf_counter() - t0
    per_vertex = operator_info(operator).unknowns_per_vertex
    modes = result.vectors
    if per_vertex > 1:
        modes = modes.reshape(mesh.n_vertices, per_vertex, k)
    spec = mv.Spectrum(
        result.eigenvalues,
        modes,
        operator,
        mass[::per_vertex],
        result.residuals,
        parameters={"null_space_dimension": result.null_dim},
    )
    t0 = time.perf_counter()
    mv.signature(spec)
    t_signature = time.perf_counter() - t0
    return {
        "mesh": size,
        "vertices": mesh.n_vertices,
        "operator": operator,
        "unknowns": K.shape[0],
        "k": k,
        "assembly_s": t_assembly,
        "eigen_s": t_eigen,
        "stage_s": result.stage_seconds,
        "operator_columns": result.operator_columns,
        "signature_s": t_signature,
        "method": result.method,
        "null_space_dimension": result.null_dim,
        "max_residual": float(result.residuals[~spec.zero_mode_mask()].max(initial=0.0)),
        "peak_mb": peak_mb(),
        "eigenvalues": result.eigenvalues.tolist(),
        "shift": result.shift,
    }


def _baseline_row(size: str, operator: str, k: int, shift: float) -> dict:
    mesh = make_mesh(size)
    K, mass = operator_matrices(mesh, operator)
    t0 = time.perf_counter()
    lam = baseline(K, mass, k, shift)
    return {
        "baseline_eigen_s": time.perf_counter() - t0,
        "baseline_peak_mb": peak_mb(),
        "eigenvalues": lam.tolist(),
    }


def _in_child(fn, *args):
    """``fn(*args)`` in a fresh process with the memory settings of the viewer's and the
    command line's computation processes (``core.memory``)."""
    import multiprocessing as mp

    with mp.get_context("spawn").Pool(1, initializer=prepare_compute_process) as pool:
        return pool.apply(fn, args)


def run(sizes, operators, k, with_baseline=True, baseline_max_unknowns=None, few=()):
    rows = []
    for size in sizes:
        for operator in operators:
            row = _in_child(_ours, size, operator, k)
            lam = np.asarray(row.pop("eigenvalues"))
            shift = row.pop("shift")
            if with_baseline and (
                baseline_max_unknowns is None or row["unknowns"] <= baseline_max_unknowns
            ):
                base = _in_child(_baseline_row, size, operator, k, shift)
                lam_base = np.asarray(base.pop("eigenvalues"))
                row.update(base)
                row["speedup"] = row["baseline_eigen_s"] / row["eigen_s"]
                # zero modes (constants, rigid motions) are rounding noise in both
                # solvers: compare their count, and the others relatively
                zero = lam < 1e-8 * np.abs(lam).max()
                row["zero_modes"] = int(zero.sum())
                row["baseline_zero_modes"] = int(
                    (np.abs(lam_base) < 1e-8 * np.abs(lam_base).max()).sum()
                )
                row["max_rel_eig_diff"] = float(
                    np.max(np.abs(lam[~zero] - lam_base[~zero]) / np.abs(lam_base[~zero]))
                )
            rows.append(row)
            print(json.dumps(row), flush=True)
    for k_few in few:  # few modes of the shells on the largest mesh
        row = _in_child(_ours, sizes[-1], "shells", k_few)
        row.pop("eigenvalues")
        row.pop("shift")
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def few_table(rows) -> str:
    """Few-mode rows against the row of the same mesh and operator with the most modes."""
    lines = [
        "| mesh | operator | k | columns | eigen s | of the k-mode time | k-mode row |",
        "|" + " --- |" * 7,
    ]
    for r in rows:
        same = [q for q in rows if (q["mesh"], q["operator"]) == (r["mesh"], r["operator"])]
        most = max(same, key=lambda q: q["k"])
        if most is r:
            continue
        lines.append(
            f"| {r['mesh']} | {r['operator']} | {r['k']} | {r.get('operator_columns', '-')} "
            f"| {r['eigen_s']:.1f} | {r['eigen_s'] / most['eigen_s']:.2f} "
            f"| k = {most['k']}, {most['eigen_s']:.1f} s |"
        )
    return "\n".join(lines)


def table(rows) -> str:
    head = (
        "| mesh | n | operator | k | assembly s | eigen s | baseline s | ratio "
        "| signature s | max rel. diff | max residual | peak MB | baseline peak MB |"
    )
    lines = [head, "|" + " --- |" * 13]

    def opt(r, key, fmt):  # "-" where the baseline was not run
        return format(r[key], fmt) if key in r else "-"

    for r in rows:
        lines.append(
            f"| {r['mesh']} | {r['vertices']} | {r['operator']} | {r['k']} | {r['assembly_s']:.2f} "
            f"| {r['eigen_s']:.1f} | {opt(r, 'baseline_eigen_s', '.1f')} "
            f"| {opt(r, 'speedup', '.2f')} | {r['signature_s']:.2f} "
            f"| {opt(r, 'max_rel_eig_diff', '.1e')} | {r['max_residual']:.1e} "
            f"| {r['peak_mb']:.0f} | {opt(r, 'baseline_peak_mb', '.0f')} |"
        )
    return "\n".join(lines)


STAGES = (
    "factorisation",
    "solves",
    "orthogonalisation",
    "restarts",
    "ritz",
    "refinement",
    "rayleigh_ritz",
    "residuals",
    "copy",
)


def stage_table(rows) -> str:
    """Where the solver's time went, per row: seconds per stage and operator columns."""
    head = (
        "| mesh | operator | k | unknowns | columns | "
        + " | ".join(STAGES)
        + " | other | eigen s |"
    )
    lines = [head, "|" + " --- |" * (len(STAGES) + 7)]
    for r in rows:
        stages = r.get("stage_s", {})
        cells = [f"{stages.get(name, 0.0):.1f}" for name in STAGES]
        other = r["eigen_s"] - sum(stages.get(name, 0.0) for name in STAGES)
        lines.append(
            f"| {r['mesh']} | {r['operator']} | {r['k']} | {r['unknowns']} "
            f"| {r.get('operator_columns', '-')} "
            f"| " + " | ".join(cells) + f" | {other:.1f} | {r['eigen_s']:.1f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", nargs="+", default=["10k", "50k", "130k"])
    p.add_argument("--operators", nargs="+", default=["laplacian", "shells"])
    p.add_argument("--k", type=int, default=300)
    p.add_argument("--no-baseline", action="store_true")
    p.add_argument(
        "--baseline-max-unknowns",
        type=int,
        default=None,
        help="skip the plain-scipy baseline above this many unknowns (it is slow)",
    )
    p.add_argument(
        "--few",
        nargs="*",
        type=int,
        default=[],
        help="also these (small) numbers of shells modes on the largest mesh",
    )
    p.add_argument("--output", default="latest", help="results file name (no extension)")
    args = p.parse_args(argv)
    rows = run(
        args.sizes,
        args.operators,
        args.k,
        not args.no_baseline,
        args.baseline_max_unknowns,
        args.few,
    )
    save_result(args.output, rows)
    print(table(rows))
    print()
    print(stage_table(rows))
    if args.few:
        print()
        print(few_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
