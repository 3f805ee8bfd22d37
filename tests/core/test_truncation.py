"""The truncation estimate of a signature (core.truncation) against the true share of the
missing modes, computed from every mode of small meshes (dense eigendecompositions)."""

import numpy as np
import pytest
import scipy.linalg as sla

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.nullspace import null_space
from modalviewer.core.primitives import icosphere, torus
from modalviewer.core.signatures import default_times
from modalviewer.core.truncation import k_for_truncation, truncation_error

MESHES = {"sphere": lambda: icosphere(2), "torus": lambda: torus(16, 8)}


def _nonzero_eigenvalues(mesh, operator):
    K, mass = operator_matrices(mesh, operator)
    lam = sla.eigh(K.toarray(), np.diag(mass), eigvals_only=True)
    return lam[null_space(mesh, operator, K, mass).dimension :]


def _true_error(lam, k, times):
    """The share of sum_v m_v S_t(v) = sum_j exp(-lambda_j t) the modes beyond k hold."""
    w = np.exp(-np.outer(lam, times))
    return w[k:].sum(axis=0) / w.sum(axis=0)


@pytest.mark.parametrize("name", MESHES)
@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet", "shells"])
@pytest.mark.parametrize("k", [20, 40])
def test_the_estimate_bounds_the_true_truncation_error(name, operator, k):
    mesh = MESHES[name]()
    lam = _nonzero_eigenvalues(mesh, operator)
    spec = mv.compute_spectrum(mesh, operator, k + int(operator == "shells") * 6 + 1)
    nonzero = int((~spec.zero_mode_mask()).sum())
    np.testing.assert_allclose(spec.eigenvalues[~spec.zero_mode_mask()], lam[:nonzero], rtol=1e-6)
    # the default scales and a hundred times below the smallest (a typed scale)
    t = default_times(spec)
    times = np.geomspace(0.01 * t[0], t[-1], 60)
    actual = _true_error(lam, nonzero, times)
    estimate = truncation_error(spec, times)
    large = actual > 0.01
    assert large.sum() >= 10
    assert np.all(estimate[large] >= actual[large])
    assert np.all(estimate[large] <= 25 * actual[large])
    assert np.all(estimate[actual > 0.05] <= 10 * actual[actual > 0.05])


def test_a_complete_spectrum_has_no_truncation_error():
    mesh = icosphere(1)
    spec = mv.compute_spectrum(mesh, "laplacian", mesh.n_vertices)
    assert np.all(truncation_error(spec, default_times(spec)[:5] * 1e-3) == 0)


@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet"])
def test_the_suggested_k_brings_the_true_error_below_the_level(operator):
    mesh = torus(16, 8)
    lam = _nonzero_eigenvalues(mesh, operator)
    spec = mv.compute_spectrum(mesh, operator, 20)
    zeros = int(spec.zero_mode_mask().sum())
    t = 0.05 * default_times(spec)[0]
    assert truncation_error(spec, [t])[0] > 0.05
    k = k_for_truncation(spec, t, 0.05)
    assert spec.k < k <= mesh.n_vertices
    assert _true_error(lam, k - zeros, [t])[0] <= 0.05
    needed = next(m for m in range(1, len(lam) + 1) if _true_error(lam, m, [t])[0] <= 0.05)
    assert k - zeros <= 2 * needed
    # a spectrum already below the level keeps its k
    assert k_for_truncation(spec, default_times(spec)[0], 0.05) == spec.k


def test_the_estimate_is_zero_not_nan_at_very_large_scales():
    # at 100 times the largest default scale every exp(-lambda t) underflows: the estimate
    # was 0 / 0 (nan, with a RuntimeWarning); the tail is nothing there
    spec = mv.compute_spectrum(torus(16, 8), "shells", 30)
    t = default_times(spec)
    times = np.array([t[-1], 100 * t[-1], 1e6 * t[-1]])
    with np.errstate(invalid="raise", divide="raise"):
        estimate = truncation_error(spec, times)
    assert np.all(np.isfinite(estimate)) and np.all(estimate[1:] == 0.0)
    assert 0.0 <= estimate[0] < 1e-3
