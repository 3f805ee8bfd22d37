"""The wave kernel signature and its distance: against a dense evaluation of the formula
(Aubry, Schlickewei, Cremers 2011) for each operator, and against pyFM's WKS."""

import numpy as np
import pytest
import scipy.linalg as la

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.primitives import icosphere
from modalviewer.core.signatures import WKS_VARIANCE, wks_sigma


@pytest.fixture(scope="module")
def small():
    rng = np.random.default_rng(5)
    base = icosphere(1)  # 42 vertices
    return mv.Mesh(base.vertices * [1.0, 0.8, 1.3] + 0.03 * rng.normal(size=(42, 3)), base.faces)


def dense_wks(mesh, operator, energies, sigma):
    """W_E(v) by the formula from a dense generalised eigendecomposition of (K, M)."""
    K, mass = operator_matrices(mesh, operator)
    lam, phi = la.eigh(K.toarray(), np.diag(mass))
    keep = lam > 1e-8 * lam.max()
    lam, phi = lam[keep], phi[:, keep]
    sq = phi**2
    if operator == "shells":  # |phi_j(v)|^2 summed over xyz
        sq = sq.reshape(mesh.n_vertices, 3, -1).sum(axis=1)
    out = np.empty((mesh.n_vertices, len(energies)))
    for i, energy in enumerate(energies):
        w = np.exp(-((np.log(energy) - np.log(lam)) ** 2) / (2 * sigma**2))
        out[:, i] = sq @ w / w.sum()
    return out


@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet", "shells"])
def test_wks_is_the_formula_on_the_full_spectrum(small, operator):
    per_vertex = 3 if operator == "shells" else 1
    spec = mv.compute_spectrum(small, operator, k=per_vertex * small.n_vertices)
    energies, values = mv.signature(spec, kind="wks")
    lam = spec.eigenvalues[~spec.zero_mode_mask()]
    # the default band: 100 energies from the smallest to the largest non-zero eigenvalue
    assert energies.shape == (100,)
    assert energies[0] == pytest.approx(lam.min(), rel=1e-12)
    assert energies[-1] == pytest.approx(lam.max(), rel=1e-12)
    sigma = WKS_VARIANCE * np.log(lam.max() / lam.min()) / 99
    assert wks_sigma(energies) == pytest.approx(sigma, rel=1e-12)
    expected = dense_wks(small, operator, energies, sigma)
    np.testing.assert_allclose(values, expected, rtol=1e-7, atol=1e-9 * expected.max())
    # at given energies, a given width and some vertices
    picked = [0, 7, 41]
    chosen = energies[[3, 50, 90]]
    _, some = mv.signature(spec, kind="wks", energies=chosen, sigma=0.4, vertices=picked)
    expected = dense_wks(small, operator, chosen, 0.4)[picked]
    np.testing.assert_allclose(some, expected, rtol=1e-7, atol=1e-9 * expected.max())


def test_wks_matches_pyfm_on_the_same_laplacian_eigenpairs(spot):
    signatures = pytest.importorskip("pyFM.signatures")
    spec = mv.compute_spectrum(spot, "laplacian", k=40)
    energies, values = mv.signature(spec, kind="wks")
    sigma = wks_sigma(energies)
    # pyFM takes log-energies; scaled=True divides by C_E as Aubry et al. and we do
    theirs = signatures.WKS(spec.eigenvalues, spec.modes, np.log(energies), sigma, scaled=True)
    np.testing.assert_allclose(values, theirs, rtol=1e-12, atol=1e-14 * theirs.max())
    # pyFM's automatic band (2 sigma inside the eigenvalues, sigma = 7 range / num_E)
    auto = signatures.auto_WKS(spec.eigenvalues, spec.modes, 50, scaled=True)
    lam = spec.eigenvalues[1:]
    s = 7 * np.log(lam.max() / lam.min()) / 50
    e = np.linspace(np.log(lam.min()) + 2 * s, np.log(lam.max()) - 2 * s, 50)
    _, ours = mv.signature(spec, kind="wks", energies=np.exp(e), sigma=s)
    np.testing.assert_allclose(ours, auto, rtol=1e-12, atol=1e-14 * auto.max())


def test_wks_distance_is_eq31_over_energies(small):
    spec = mv.compute_spectrum(small, "modified_dirichlet", k=30)
    energies, w = mv.signature(spec, kind="wks", energies=np.geomspace(2.0, 60.0, 40))
    d = mv.multiscale_distance(spec, 9, t_range=(2.0, 60.0), samples=40, kind="wks")
    dloge = np.log(60.0 / 2.0) / 39
    expected = np.sqrt(((w - w[9]) ** 2).sum(axis=1) * dloge)
    np.testing.assert_allclose(d, expected, rtol=1e-10, atol=1e-12 * expected.max())
    assert d[9] == 0.0
    # the default range is the default energies'
    table = mv.SignatureTable(spec, kind="wks")
    np.testing.assert_allclose(table.times, mv.default_energies(spec), rtol=1e-15)
    heat = mv.multiscale_distance(spec, 9)
    assert not np.allclose(heat / heat.max(), table.distance_from(9) / table.distance_from(9).max())


def test_wks_refuses_what_it_does_not_take(small):
    spec = mv.compute_spectrum(small, "laplacian", k=10)
    with pytest.raises(ValueError, match="energies="):
        mv.signature(spec, times=[1.0], kind="wks")
    with pytest.raises(ValueError, match="kind"):
        mv.signature(spec, kind="wave")
    with pytest.raises(ValueError, match='kind="wks"'):
        mv.signature(spec, energies=[1.0])
    with pytest.raises(ValueError, match="positive"):
        mv.signature(spec, kind="wks", energies=[-1.0])
    with pytest.raises(ValueError, match="sigma"):
        mv.signature(spec, kind="wks", sigma=0.0)
