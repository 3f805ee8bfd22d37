"""The memory of the exact solver's factorisation against mesh size, in core and out of
core, from PARDISO's analysis (no numerical factorisation, so a million vertices take
seconds).

    python -m benchmarks.factor_memory [--grids 320 580 1000] [--curved spot:loop:3 ...]

For each operator, ``K - shift M`` (the solver's shift) of the bumpy plate on n x n
grids (102k, 336k and 1M vertices by default) and of Loop-subdivided bundled meshes
(:mod:`benchmarks.curved`'s cases) goes through
:func:`factor_memory_mb`.  The plates' sizes are fitted as
power laws of the vertex count (MB at 100k vertices and exponent, in core and out of
core): the laws the memory check uses for a factor that goes out of core
(:meth:`modalviewer.core.operators.OperatorInfo.predicted_peak_mb`); the curved rows say
how far real meshes are from them.  Writes ``benchmarks/results/factor_memory.json``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.curved import ASSETS, case_mesh, case_name, parse_case  # noqa: E402
from benchmarks.growth import fit_growth  # noqa: E402
from benchmarks.run import save_result  # noqa: E402


def factor_memory_mb(A) -> tuple[float, float]:
    """(in core, out of core): the memory (MB) PARDISO's factorisation of A needs, from
    its analysis alone (no numerical factorisation)."""
    import scipy.sparse as sp

    from modalviewer.core.factor import _load_mkl, _Pardiso

    if _load_mkl() is None:
        raise SystemExit("these sizes come from PARDISO's analysis: install the mkl wheel")
    analysis = _Pardiso(sp.csr_matrix(A), _load_mkl(), factorise=False)
    try:
        return analysis.in_core_mb, analysis.out_of_core_mb
    finally:
        analysis.release()


def _sizes(mesh, operator: str) -> dict:
    import scipy.sparse as sp

    from modalviewer.core.assembly import operator_matrices
    from modalviewer.core.eigen import SHIFT_RTOL, typical_eigenvalue

    K, mass = operator_matrices(mesh, operator)
    shift = -SHIFT_RTOL * typical_eigenvalue(K, mass)
    in_core, out_of_core = factor_memory_mb(K - shift * sp.diags(mass))
    return {
        "vertices": mesh.n_vertices,
        "unknowns": K.shape[0],
        "operator": operator,
        "in_core_mb": round(in_core, 1),
        "out_of_core_mb": round(out_of_core, 1),
    }


def fits(rows: list[dict]) -> list[dict]:
    """Per operator: the in-core and out-of-core sizes as power laws of the vertices."""
    out = []
    for operator in dict.fromkeys(r["operator"] for r in rows):
        sel = [r for r in rows if r["operator"] == operator]
        core, ooc = fit_growth(sel, "in_core_mb"), fit_growth(sel, "out_of_core_mb")
        if core and ooc:
            out.append(
                {
                    "operator": operator,
                    "in_core_mb_at_100k": round(core[0], 1),
                    "in_core_exponent": round(core[1], 3),
                    "out_of_core_mb_at_100k": round(ooc[0], 1),
                    "out_of_core_exponent": round(ooc[1], 3),
                }
            )
    return out


def main(argv=None) -> int:
    from modalviewer.core.demo_shapes import bumpy_plate
    from modalviewer.core.operators import OPERATOR_NAMES

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grids", type=int, nargs="+", default=[320, 580, 1000])
    parser.add_argument(
        "--curved", type=parse_case, nargs="*", default=[parse_case("spot:loop:3"),
                                                          parse_case("hand:loop:2")],
    )  # fmt: skip
    parser.add_argument("--operators", nargs="+", default=list(OPERATOR_NAMES))
    args = parser.parse_args(argv)
    plates, curved = [], []
    for grid in args.grids:
        mesh = bumpy_plate(grid)
        for operator in args.operators:
            plates.append({"grid": grid, **_sizes(mesh, operator)})
            print(plates[-1], flush=True)
    for case in args.curved:
        asset, scheme, level = case
        mesh = case_mesh(ASSETS[asset], scheme, level)
        for operator in args.operators:
            curved.append({"mesh": case_name(case), **_sizes(mesh, operator)})
            print(curved[-1], flush=True)
    save_result("factor_memory", {"plates": plates, "curved": curved, "fits": fits(plates)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
