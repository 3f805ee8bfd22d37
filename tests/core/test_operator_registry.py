"""A new operator is one entry of the registry and its assembly function: nothing else
in the package names operators, so the spectrum, its null space, its file and the
cache work for it as they do for the built-in ones."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.cache import SpectrumCache
from modalviewer.core.laplacian import stiffness_matrix
from modalviewer.core.operators import OPERATOR_INFO, OperatorInfo, operator_info
from modalviewer.core.primitives import torus


def twice_the_laplacian(mesh):
    """The toy operator's assembly function: the cotan Laplacian scaled by 2."""
    return 2.0 * stiffness_matrix(mesh)


TOY = OperatorInfo(
    "twice_laplacian",
    "Laplacian times two",
    "2 Laplacian",
    unknowns_per_vertex=1,
    distance_kind=None,
    has_weights=False,
    assemble=twice_the_laplacian,
    null_space="constants",
    null_space_rule="constants",
    exact_growth=OPERATOR_INFO["laplacian"].exact_growth,
)


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(OPERATOR_INFO, TOY.name, TOY)
    return TOY


@pytest.fixture(scope="module")
def ring():
    return torus(48, 32)  # 1,536 vertices: above the dense limit, the Krylov solver runs


def test_a_registered_operator_has_the_spectrum_of_its_matrix(registered, ring, tmp_path):
    lap = mv.compute_spectrum(ring, "laplacian", k=12)
    toy = mv.compute_spectrum(ring, "twice_laplacian", k=12)
    assert toy.operator == "twice_laplacian"
    assert toy.parameters["method"].startswith("shift-invert")
    assert toy.null_space_dimension == 1  # the constant, from the registry's rule
    np.testing.assert_allclose(toy.eigenvalues[1:], 2.0 * lap.eigenvalues[1:], rtol=1e-8)
    # the same eigenspaces: each of the first modes lies in the span of the Laplacian's
    # (the torus's eigenvalues come in pairs, so single modes need not agree)
    inside = np.linalg.norm(lap.modes.T @ (lap.mass[:, None] * toy.modes[:, :9]), axis=0)
    np.testing.assert_allclose(inside, 1.0, atol=1e-6)
    assert float(np.max(toy.residuals[1:])) < 1e-8
    path = tmp_path / "toy.npz"
    mv.save_spectrum(toy, path)
    back = mv.load_spectrum(path)
    assert back.operator_info is TOY
    np.testing.assert_array_equal(back.eigenvalues, toy.eigenvalues)
    cache = SpectrumCache(tmp_path / "cache")
    cache.put(ring, toy, 12)
    np.testing.assert_array_equal(cache.get(ring, TOY, 12).eigenvalues, toy.eigenvalues)


def test_the_operator_object_travels_in_place_of_its_name(ring):
    by_name = mv.compute_spectrum(ring, "laplacian", k=8)
    by_object = mv.compute_spectrum(ring, operator_info("laplacian"), k=8)
    assert by_object.operator == "laplacian"
    np.testing.assert_array_equal(by_object.eigenvalues, by_name.eigenvalues)
    unregistered = mv.compute_spectrum(ring, TOY, k=8)  # an object needs no registry entry
    np.testing.assert_allclose(unregistered.eigenvalues[1:], 2 * by_name.eigenvalues[1:], rtol=1e-8)


def test_an_unknown_operator_is_named_with_the_known_ones():
    with pytest.raises(ValueError, match="unknown operator 'bogus'; choose one of laplacian"):
        operator_info("bogus")
    with pytest.raises(ValueError, match="unknown operator 3"):
        operator_info(3)
