"""The memory predictions: growth laws from the measured runs, and their arithmetic."""

import json
from pathlib import Path

import numpy as np
import pytest

from benchmarks.growth import _fits
from benchmarks.memory import relative_differences
from modalviewer.core.memory import FILL_MARGIN, GrowthLaw
from modalviewer.core.operators import OPERATOR_INFO, operator_info

RESULTS = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "growth.json"
MORE_MODES = RESULTS.with_name("growth_k300.json")


def test_every_operators_growth_law_is_the_fit_of_the_measured_runs():
    """The laws in the operator registry are not typed numbers: they are what
    benchmarks.growth fits to benchmarks/results/growth.json (rounded as it writes them)."""
    fits = {f["operator"]: f for f in _fits(json.loads(RESULTS.read_text())["rows"])}
    for name, info in OPERATOR_INFO.items():
        fit = fits[info.measured_as or name]  # an operator borrowing another's law
        assert info.exact_growth == GrowthLaw(fit["peak_mb_at_100k"], fit["memory_exponent"])


def test_the_laws_reproduce_the_runs_they_were_fitted_to_within_a_third():
    """A power law through 100k..1M: every measured run from 100k on within a factor 1.35
    of its predicted peak memory."""
    checked = 0
    for r in json.loads(RESULTS.read_text())["rows"]:
        if "peak_mb" not in r or r["vertices"] < 100_000:
            continue
        info = operator_info(r["operator"])
        # the runs kept their factors in core
        m = info.predicted_peak_mb(r["vertices"], out_of_core=False, basis_float32=False)
        assert 1 / 1.35 < r["peak_mb"] / m < 1.35, (r, m)
        checked += 1
    assert checked >= 12


def test_the_law_is_a_power_of_size():
    law = GrowthLaw(500.0, 0.8)
    assert law.peak_mb(100_000) == pytest.approx(500.0)
    assert law.peak_mb(400_000) == pytest.approx(500.0 * 4**0.8)


CURVED = RESULTS.with_name("curved.json")


def test_exact_peak_memory_is_predicted_for_other_mode_counts_and_curved_meshes():
    """The memory check's prediction (the law at 100 modes plus the arrays that grow
    with k, the factor counted at FILL_MARGIN times its law) against runs it was not
    fitted to: 300 modes on the 337k plate for every operator and the exact solves on
    the curved meshes (spot, the hand, the cow and Cheburashka Loop-subdivided: thin
    legs, ears, fingers; the machined part, flat walls and sharp edges).  A run may need
    at most 5 % more than predicted (at the check's limit of three quarters of the
    memory it still fits) and not much less, or the check would refuse what fits.  The
    300-mode runs need 0.82 to 0.83 of the prediction (it counts every further mode's
    basis and mode columns in full, more than the solve's peak holds at once, and the
    plate's factor at its law); the curved meshes from 100k vertices 0.92 to 1.02.
    Without the fill margin the 3D shells of spot Loop x3 and hand Loop x2 needed 1.15
    and 1.14 of the prediction: their factors fill in 1.26 and 1.23 times what the
    plates' factor law gives (benchmarks/results/factor_memory.json's curved rows).  One
    exception measured: the part's 3D shells need 0.67 (its factor fills in less than
    the plate's the law comes from, so the check errs on the side of refusing there)."""
    checked = 0
    for r in json.loads(MORE_MODES.read_text())["rows"]:
        if "peak_mb" not in r:
            continue
        info = operator_info(r["operator"])
        m = info.predicted_peak_mb(r["vertices"], r["k"], out_of_core=False, basis_float32=False)
        assert 0.8 < r["peak_mb"] / m < 1.05, (r, m)
        checked += 1
    for r in json.loads(CURVED.read_text())["rows"]:
        if r["vertices"] < 100_000:
            continue
        info = operator_info(r["operator"])
        m = info.predicted_peak_mb(r["vertices"], r["k"], out_of_core=False, basis_float32=False)
        part_shells = r["mesh"].startswith("part") and r["operator"] == "shells"
        low = 0.6 if part_shells else 0.88
        high = 1.05
        assert low < r["exact_peak_mb"] / m < high, (r, m)
        checked += 1
    assert checked >= 10


def test_the_fill_margin_covers_the_curved_factors_measured():
    """FILL_MARGIN is the largest in-core factor size of the curved meshes that PARDISO
    analysed (benchmarks/results/factor_memory.json) over the plates' factor law, to two
    decimals: spot Loop x3's 3D shells, 1.256."""
    data = json.loads(RESULTS.with_name("factor_memory.json").read_text())
    ratios = [
        r["in_core_mb"] / operator_info(r["operator"]).factor_memory.in_core_mb(r["vertices"])
        for r in data["curved"]
    ]
    assert len(ratios) >= 8
    assert max(ratios) <= FILL_MARGIN < max(ratios) + 0.01, ratios


def test_more_modes_need_their_basis_and_mode_columns_and_no_more():
    """Between two mode counts the prediction differs by exactly the Krylov basis
    columns (the solver's own sizes) and the mode columns of N doubles each."""
    from modalviewer.core.memory import BASIS_EXTRA_MAX, basis_columns, krylov_sizes

    info = operator_info("shells")
    n_vertices = 200_000
    n = info.unknowns(n_vertices)
    at_100 = info.predicted_peak_mb(n_vertices, 100)
    at_300 = info.predicted_peak_mb(n_vertices, 300)
    _, block, max_basis, _ = krylov_sizes(300, n)
    assert basis_columns(300, n) == max_basis + block
    assert max_basis - krylov_sizes(300, n)[0] <= BASIS_EXTRA_MAX + block  # a big basis: capped
    columns = basis_columns(300, n) - basis_columns(100, n) + 200
    assert at_300 - at_100 == pytest.approx(8.0 * n * columns / 2**20, rel=1e-12)
    further_fill = (FILL_MARGIN - 1) * info.factor_memory.in_core_mb(n_vertices)
    assert at_100 == pytest.approx(info.exact_growth.peak_mb(n_vertices) + further_fill, rel=1e-12)
    assert info.predicted_peak_mb(n_vertices, 10) < at_100


FACTOR_MEMORY = RESULTS.with_name("factor_memory.json")
BIG_SOLVES = RESULTS.with_name("memory.json")


def test_every_operators_factor_law_is_the_fit_of_the_measured_analyses():
    """The factor sizes in the registry are what benchmarks.factor_memory fits to
    benchmarks/results/factor_memory.json, and they reproduce the plates they were fitted
    to within 15 %."""
    from benchmarks.factor_memory import fits
    from modalviewer.core.memory import FactorLaw

    data = json.loads(FACTOR_MEMORY.read_text())
    for fit in fits(data["plates"]):
        law = operator_info(fit["operator"]).factor_memory
        assert law == FactorLaw(
            fit["in_core_mb_at_100k"],
            fit["in_core_exponent"],
            fit["out_of_core_mb_at_100k"],
            fit["out_of_core_exponent"],
        )
    for r in data["plates"]:
        law = operator_info(r["operator"]).factor_memory
        assert 1 / 1.15 < r["in_core_mb"] / law.in_core_mb(r["vertices"]) < 1.15, r
        assert 1 / 1.15 < r["out_of_core_mb"] / law.out_of_core_mb(r["vertices"]) < 1.15, r


def test_big_solves_need_what_the_memory_check_predicts_for_their_choice():
    """Runs the laws were not fitted to (curved meshes, 300 modes), factor in core or out
    of core: at most 10 % more than predicted (the check keeps a quarter of the memory
    free) and not much less (25 %: out of core the prediction takes the plate's factor
    sizes, and curved meshes save more; the 520k plate's 300 modes need 0.84 of it),
    and the same eigenvalues either way."""
    rows = json.loads(BIG_SOLVES.read_text())["rows"]
    assert any(r["factor_out_of_core"] for r in rows)
    for r in rows:
        info = operator_info(r["operator"])
        ooc, single = bool(r["factor_out_of_core"]), bool(r.get("basis_float32"))
        m = info.predicted_peak_mb(r["vertices"], r["k"], out_of_core=ooc, basis_float32=single)
        assert 0.75 < r["peak_mb"] / m < 1.1, (r["mesh"], r["limit_mb"], r["peak_mb"], m)
        # a single-precision basis on either side: the same eigenvalues within what the
        # residuals allow; double on both: to the last digit
        others = [q for q in rows if r.get("compared_with", "").startswith(q["mesh"])]
        single_either = single or any(q.get("basis_float32") for q in others)
        if "compared_with" not in r:  # the reference of its run
            assert r["largest_relative_difference"] == 0.0
        elif single_either:
            # the stored run benchmarks.memory compared with: the first of that label
            reference = next(q for q in others if "eigenvalues" in q)
            difference = relative_differences(
                np.array(r["eigenvalues"]), np.array(reference["eigenvalues"])
            )
            assert np.all(difference <= _residual_bounds(r, reference)), r["mesh"]
            assert r["largest_relative_difference"] == pytest.approx(difference.max())
        else:
            assert r["largest_relative_difference"] < 1e-10
        assert r["mass_orthonormality"] < 1e-10


def _residual_bounds(row: dict, reference: dict) -> np.ndarray:
    """Per mode, how far apart two runs' eigenvalues may be: a Ritz value whose relative
    residual is rho lies within ``rho^2 lam / gap`` of its eigenvalue (relative), gap the
    distance to the nearest other eigenvalue; both runs' largest residuals count.  Zero
    modes: 1e-12 of the largest eigenvalue, the differences' own floor.  Two
    double-precision solves of the 1M plate made with different memory settings differ
    by 1.4e-8 at its ninth mode (1418.84, 20.3 from its neighbour, residuals 4.5e-5:
    bound 2.8e-7), so a fixed tolerance of 1e-8 would be the luck of one pair of runs."""
    lam, ref = np.array(row["eigenvalues"]), np.array(reference["eigenvalues"])
    m = min(lam.shape[0], ref.shape[0])
    ref = ref[:m]
    rho2 = row["max_residual"] ** 2 + reference["max_residual"] ** 2
    gaps = np.full(m, np.inf)
    neighbours = np.abs(np.diff(ref))
    gaps[:-1] = neighbours
    gaps[1:] = np.minimum(gaps[1:], neighbours)
    # the last compared mode's upper neighbour is not known: the gap below it stands in
    zero = np.abs(ref) <= 1e-8 * np.abs(ref).max()
    return np.where(zero, 1e-12, rho2 * np.abs(ref) / np.maximum(gaps, 1e-300))


def test_the_memory_check_predicts_the_factor_out_of_core_where_it_would_not_fit():
    info = operator_info("shells")
    n, k = 520_000, 300  # 1.56M unknowns
    in_core = info.predicted_peak_mb(n, k, out_of_core=False, basis_float32=False)
    out_of_core = info.predicted_peak_mb(n, k, out_of_core=True, basis_float32=False)
    law = info.factor_memory
    saved = law.in_core_mb(n) - law.out_of_core_mb(n)
    assert in_core - out_of_core == pytest.approx(FILL_MARGIN * saved)
    assert out_of_core < 0.85 * in_core
    # the solver's rule: out of core only where the in-core peak is above the limit
    assert info.factor_out_of_core(n, k, limit_mb=0.9 * in_core)
    assert not info.factor_out_of_core(n, k, limit_mb=1.1 * in_core)
    # the scalar operators' factors are small: out of core would not save memory there
    lap = operator_info("laplacian")
    assert not lap.factor_out_of_core(100_000, 100, limit_mb=1.0)


def test_a_single_precision_basis_is_predicted_as_its_buffer_and_chosen_over_the_limit():
    from modalviewer.core.memory import (
        float32_basis_mb,
        float32_basis_saving_mb,
        krylov_sizes,
        memory_limit_mb,
    )

    info = operator_info("shells")
    n_vertices, k = 1_002_001, 300
    n = info.unknowns(n_vertices)
    _, block, max_basis, _ = krylov_sizes(k, n)
    columns = max_basis + block
    double = info.predicted_peak_mb(n_vertices, k, out_of_core=True, basis_float32=False)
    single = info.predicted_peak_mb(n_vertices, k, out_of_core=True, basis_float32=True)
    # the double basis and the 200 mode columns above the law's 100, against one buffer
    beside = 8.0 * n * (columns + 200) / 2**20
    assert float32_basis_saving_mb(n, k) == pytest.approx(beside - float32_basis_mb(n, columns, k))
    assert double - single == pytest.approx(float32_basis_saving_mb(n, k), rel=1e-12)
    # the memory check's default mirrors the solver: single precision where the peak with
    # the factor out of core is still above the limit
    limit = memory_limit_mb()
    default = info.predicted_peak_mb(n_vertices, k)
    assert default == pytest.approx(single if double > limit else double, rel=1e-12)
    # a mesh where the double basis fits keeps it
    assert info.predicted_peak_mb(20_000, 100) == pytest.approx(
        info.predicted_peak_mb(20_000, 100, out_of_core=False, basis_float32=False)
    )
