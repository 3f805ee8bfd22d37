"""local_signature (Lemma 2) equals the spectral sum over all modes, computed here from
dense generalised eigendecompositions, for the three signatures."""

import numpy as np
import pytest
import scipy.linalg as sla

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.nullspace import null_space
from modalviewer.core.primitives import grid_plate, icosphere, torus

MESHES = {
    "sphere": lambda: icosphere(1),
    "plate": lambda: grid_plate(6, 6),
    "torus": lambda: torus(10, 6),
}
OPERATORS = ("laplacian", "modified_dirichlet", "shells")


def _dense_signature(mesh, operator, vertices, times, include_zero):
    """sum_j exp(-lambda_j t) |phi_j(v)|^2 over every mode of the dense problem."""
    K, mass = operator_matrices(mesh, operator)
    lam, phi = sla.eigh(K.toarray(), np.diag(mass))  # M-orthonormal columns
    keep = np.ones(len(lam), dtype=bool)
    if not include_zero:
        d = null_space(mesh, operator, K, mass).dimension
        assert np.all(np.abs(lam[:d]) < 1e-8 * lam[-1])  # the null space found whole
        assert lam[d] > 1e-6 * lam[-1]
        keep[:d] = False
    per = 3 if operator == "shells" else 1
    rows = phi.reshape(mesh.n_vertices, per, -1)[vertices]  # (p, per, N)
    squared = (rows**2).sum(axis=1)[:, keep]
    return squared @ np.exp(-np.outer(np.maximum(lam[keep], 0.0), times))


def _times(mesh, operator):
    K, mass = operator_matrices(mesh, operator)
    lam = sla.eigh(K.toarray(), np.diag(mass), eigvals_only=True)
    lam = lam[lam > 1e-6 * lam[-1]]
    # from 1/100 of the smallest default scale to the largest: small scales are where
    # truncated spectra fail
    return np.geomspace(0.01 * 4 * np.log(10) / lam[-1], 4 * np.log(10) / lam[0], 15)


@pytest.mark.parametrize("name", MESHES)
@pytest.mark.parametrize("operator", OPERATORS)
@pytest.mark.parametrize("include_zero", [False, True])
def test_local_signature_equals_the_full_spectral_sum(name, operator, include_zero):
    mesh = MESHES[name]()
    vertices = [0, 7, mesh.n_vertices - 1]
    times = _times(mesh, operator)
    expected = _dense_signature(mesh, operator, vertices, times, include_zero)
    got = mv.local_signature(mesh, operator, vertices, times, include_zero=include_zero)
    assert got.shape == (3, len(times))
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=0)


def test_it_matches_signature_of_a_complete_spectrum_and_beats_a_truncated_one():
    mesh = icosphere(2)  # 162 vertices, 486 shells unknowns
    full = mv.compute_spectrum(mesh, "shells", k=3 * mesh.n_vertices)
    truncated = mv.compute_spectrum(mesh, "shells", k=60)
    t1 = mv.default_times(truncated)[0]
    times = np.array([t1 / 10, t1, 10 * t1])
    _, from_full = mv.signature(full, times, vertices=[3])
    _, from_truncated = mv.signature(truncated, times, vertices=[3])
    local = mv.local_signature(mesh, "shells", 3, times)
    np.testing.assert_allclose(local, from_full, rtol=1e-6)
    missing = 1 - from_truncated[0] / local[0]
    # the truncated sum misses positive terms: most of it a decade below its smallest
    # default scale, little at that scale, nothing visible a decade above
    assert missing[0] > 0.5 and 0 < missing[1] < 1e-2 and abs(missing[2]) < 1e-8, missing


def test_bad_arguments_are_refused():
    mesh = icosphere(1)
    with pytest.raises(TypeError, match="integer"):
        mv.local_signature(mesh, "laplacian", 2.0, [1.0])
    with pytest.raises(IndexError, match="out of range"):
        mv.local_signature(mesh, "laplacian", mesh.n_vertices, [1.0])
    with pytest.raises(ValueError):
        mv.local_signature(mesh, "laplacian", 0, [-1.0])


@pytest.mark.parametrize("operator", OPERATORS)
@pytest.mark.parametrize("include_zero", [False, True])
def test_with_a_spectrum_the_sum_is_still_over_all_modes(operator, include_zero):
    mesh = torus(10, 6)
    spec = mv.compute_spectrum(mesh, operator, k=40)
    vertices = [0, 7, mesh.n_vertices - 1]
    times = _times(mesh, operator)
    expected = _dense_signature(mesh, operator, vertices, times, include_zero)
    got = mv.local_signature(
        mesh, operator, vertices, times, include_zero=include_zero, spectrum=spec
    )
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=0)


def test_a_spectrum_of_another_operator_is_refused():
    mesh = icosphere(1)
    spec = mv.compute_spectrum(mesh, "laplacian", k=10)
    with pytest.raises(ValueError, match="this mesh and operator"):
        mv.local_signature(mesh, "shells", 0, [1.0], spectrum=spec)
