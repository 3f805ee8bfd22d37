"""Signatures and distances: Lemma 2 against expm, defaults of the spec, metric axioms."""

from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg as la

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.primitives import icosphere


@pytest.fixture(scope="module")
def small():
    rng = np.random.default_rng(11)
    base = icosphere(1)  # 42 vertices, 126 unknowns
    return mv.Mesh(base.vertices * [1.0, 0.7, 1.2] + 0.02 * rng.normal(size=(42, 3)), base.faces)


def test_lemma2_vibration_signature_equals_gradient_flow(small):
    n = small.n_vertices
    full = mv.compute_spectrum(small, "shells", k=3 * n)  # the full eigendecomposition
    H, mass3 = operator_matrices(small, "shells")
    H = H.toarray()
    Minv = np.diag(1.0 / mass3)
    lam_pos = full.eigenvalues[full.eigenvalues > 1e-8 * full.eigenvalues.max()]
    for t in (
        0.3 / lam_pos.min(),
        1.0 / lam_pos.max(),
        3.0 / np.sqrt(lam_pos.min() * lam_pos.max()),
    ):
        E = la.expm(-t * Minv @ H)
        _, sig = mv.signature(full, times=[2 * t], include_zero=True)
        for v in (0, 17, 41):
            total = 0.0
            for alpha in range(3):
                e = np.zeros(3 * n)
                e[3 * v + alpha] = 1.0
                u = E @ (Minv @ e)
                total += u @ (mass3 * u)
            assert sig[v, 0] == pytest.approx(total, rel=1e-8)


def test_default_times_follow_the_convention(spot):
    spec = mv.compute_spectrum(spot, "laplacian", k=30)
    times, values = mv.signature(spec)
    lam = spec.eigenvalues[1:]
    assert times.shape == (100,) and values.shape == (spot.n_vertices, 100)
    assert times[0] == pytest.approx(4 * np.log(10) / lam.max(), rel=1e-14)
    assert times[-1] == pytest.approx(4 * np.log(10) / lam.min(), rel=1e-14)
    # HKS by the formula, directly
    t = times[37]
    direct = (spec.modes[:, 1:] ** 2) @ np.exp(-lam * t)
    np.testing.assert_allclose(values[:, 37], direct, rtol=1e-12)
    _, with_zero = mv.signature(spec, times=[t], include_zero=True)
    np.testing.assert_allclose(with_zero[:, 0] - direct, spec.modes[:, 0] ** 2, rtol=1e-10)


@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet", "shells"])
def test_distance_is_a_pseudometric(spot, operator):
    spec = mv.compute_spectrum(spot, operator, k=30)
    rng = np.random.default_rng(5)
    picks = rng.choice(spot.n_vertices, 12, replace=False)
    D = np.array([mv.multiscale_distance(spec, int(v)) for v in picks])  # (12, n)
    assert np.all(D >= 0)
    np.testing.assert_allclose(D[np.arange(12), picks], 0.0, atol=1e-15)
    sub = D[:, picks]
    np.testing.assert_allclose(sub, sub.T, rtol=1e-10, atol=1e-15)
    # triangle inequality d(a, c) <= d(a, b) + d(b, c) over all triples
    lhs = sub[:, None, :]
    rhs = sub[:, :, None] + sub[None, :, :]
    assert np.all(lhs <= rhs + 1e-12 * sub.max())


def test_distance_equals_riemann_sum_of_eq31(spot):
    spec = mv.compute_spectrum(spot, "modified_dirichlet", k=25)
    t1, t2 = 1e-3, 1e-1
    times, S = mv.signature(spec, times=np.exp(np.linspace(np.log(t1), np.log(t2), 50)))
    lam = spec.eigenvalues
    Z = np.exp(-np.outer(lam, times)).sum(axis=0)
    dlogt = (np.log(t2) - np.log(t1)) / 49
    v = 123
    expected = np.sqrt((((S - S[v]) / Z) ** 2).sum(axis=1) * dlogt)
    got = mv.multiscale_distance(spec, v, t_range=(t1, t2), samples=50)
    np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-14)
    with pytest.raises(IndexError):
        mv.multiscale_distance(spec, spot.n_vertices)


@pytest.mark.parametrize("operator", ["shells", "modified_dirichlet"])
def test_fast_distance_query_matches_the_direct_difference(spot, operator):
    from modalviewer.core.signatures import SignatureTable

    spec = mv.compute_spectrum(spot, operator, k=30)
    # duplicate rows: vertices with identical signatures must be at distance exactly 0
    rows = np.r_[np.arange(spot.n_vertices), np.arange(5)]
    table = SignatureTable(replace(spec, modes=spec.modes[rows], mass=spec.mass[rows]))
    np.testing.assert_array_equal(table.table[-5:], table.table[:5])
    for v in (0, 3, 777):
        fast = table.distance_from(v)
        direct = np.linalg.norm(table.table - table.table[v], axis=1)
        np.testing.assert_allclose(fast, direct, rtol=1e-7, atol=1e-12 * direct.max())
        assert fast[v] == 0.0
    assert table.distance_from(3)[spot.n_vertices + 3] == 0.0


def test_signature_at_chosen_vertices_equals_the_full_rows(spot):
    spec = mv.compute_spectrum(spot, "shells", k=20)
    times, full = mv.signature(spec)
    _, some = mv.signature(spec, times, vertices=[5, 17, 5])
    np.testing.assert_allclose(some, full[[5, 17, 5]], rtol=1e-12)
