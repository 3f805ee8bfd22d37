"""operator="laplacian_robust": robust_laplacian's intrinsic Delaunay Laplacian and mass
through the registry, its null space, the negative cotan weights it avoids, the error
without the package, and a toy operator added through the registry alone."""

import sys
from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla

import modalviewer as mv
from benchmarks.slivers import add_slivers
from modalviewer.core import operators
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.primitives import icosphere
from modalviewer.core.robust import negative_cotan_weights
from modalviewer.extras import MissingExtraError


@pytest.fixture(scope="module")
def slivered():
    """A sphere of 642 vertices with 20 needles and 20 caps of quality 1e-8."""
    v, f = add_slivers(icosphere(3), needles=20, caps=20, eps=1e-8, seed=2)
    return mv.Mesh(v, f)


def test_the_spectrum_is_robust_laplacians_with_eigsh(spot):
    robust_laplacian = pytest.importorskip("robust_laplacian")
    L, M = robust_laplacian.mesh_laplacian(spot.vertices, spot.faces)
    expected = sla.eigsh(L.tocsc(), k=30, M=M.tocsc(), sigma=-1e-8, which="LM")[0]
    spec = mv.compute_spectrum(spot, "laplacian_robust", k=30)
    np.testing.assert_allclose(spec.eigenvalues[1:], np.sort(expected)[1:], rtol=1e-10)
    assert abs(spec.eigenvalues[0]) < 1e-10 * spec.eigenvalues[-1]
    # its own mass, not the cotan Laplacian's lumped areas
    np.testing.assert_allclose(spec.mass, M.diagonal(), rtol=1e-15)
    K, m = operator_matrices(spot, "laplacian_robust")
    assert isinstance(K, sp.csr_matrix) and abs(K - L).max() == 0.0
    # the constant is the exact null vector, deflated
    assert spec.null_space_dimension == 1
    np.testing.assert_allclose(np.abs(spec.modes[:, 0]), 1 / np.sqrt(m.sum()), rtol=1e-10)


def test_two_components_have_two_constants():
    pytest.importorskip("robust_laplacian")
    a, b = icosphere(1), icosphere(1)
    mesh = mv.Mesh(
        np.vstack([a.vertices, b.vertices + [3.0, 0, 0]]),
        np.vstack([a.faces, b.faces + a.n_vertices]),
    )
    spec = mv.compute_spectrum(mesh, "laplacian_robust", k=6)
    assert spec.null_space_dimension == 2
    assert np.count_nonzero(spec.zero_mode_mask()) == 2


def test_slivers_give_negative_cotan_weights_and_none_intrinsically(slivered):
    pytest.importorskip("robust_laplacian")
    assert negative_cotan_weights(icosphere(3)) == 0
    # counted directly on the assembled cotan matrix: its positive off-diagonal entries
    S = sp.triu(mv.stiffness_matrix(slivered), k=1).tocoo()
    direct = int(np.count_nonzero(S.data > 1e-12 * np.abs(S.data).max()))
    assert negative_cotan_weights(slivered) == direct == 46
    K, _ = operator_matrices(slivered, "laplacian_robust")
    off = sp.triu(K, k=1).tocoo().data
    assert off.max() <= 0.0  # intrinsic Delaunay: every weight non-negative
    spec = mv.compute_spectrum(slivered, "laplacian_robust", k=10)
    clean = mv.compute_spectrum(icosphere(3), "laplacian", k=10)
    # the slivers hardly change the surface: the spectrum stays the sphere's
    np.testing.assert_allclose(spec.eigenvalues[1:], clean.eigenvalues[1:], rtol=0.02)


def test_without_the_package_the_error_names_the_extra(spot, monkeypatch):
    monkeypatch.setitem(sys.modules, "robust_laplacian", None)
    with pytest.raises(MissingExtraError, match=r"pip install \"modalviewer\[robust\]\""):
        mv.compute_spectrum(spot, "laplacian_robust", k=5)


def test_a_new_operator_is_one_registry_entry(spot, monkeypatch):
    """A toy operator, twice the cotan Laplacian with the robust mass, added to the
    registry alone, goes through compute_spectrum, the null space and the cache key."""
    from modalviewer.core import laplacian

    def toy(mesh):
        return 2.0 * laplacian.stiffness_matrix(mesh), laplacian.lumped_masses(mesh) * 0.5

    monkeypatch.setattr(laplacian, "toy_operator", toy, raising=False)
    info = replace(
        operators.OPERATOR_INFO["laplacian"],
        name="toy",
        label="Toy",
        wave_distance_kind=None,
        distance_kind=None,
        assemble="laplacian:toy_operator",
        assembles_mass=True,
        measured_as="laplacian",
    )
    monkeypatch.setitem(operators.OPERATOR_INFO, "toy", info)
    spec = mv.compute_spectrum(spot, "toy", k=8)
    cotan = mv.compute_spectrum(spot, "laplacian", k=8)
    # K -> 2K, M -> M/2: eigenvalues times 4
    np.testing.assert_allclose(spec.eigenvalues[1:], 4 * cotan.eigenvalues[1:], rtol=1e-9)
    assert spec.operator == "toy" and spec.null_space_dimension == 1
