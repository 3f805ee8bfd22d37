"""Modified Dirichlet energy: A == S on a plate, A ~ S + 2/r^2 on a sphere."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import grid_plate, icosphere


def test_equals_stiffness_on_flat_plate():
    mesh = grid_plate(12, 9, width=1.3, height=1.0)
    A = mv.modified_dirichlet_matrix(mesh)
    S = mv.stiffness_matrix(mesh)
    assert abs(A - S).max() <= 1e-15 * abs(S).max()


def test_diagonal_equals_stiffness_and_symmetric(spot):
    A = mv.modified_dirichlet_matrix(spot)
    S = mv.stiffness_matrix(spot)
    np.testing.assert_allclose(A.diagonal(), S.diagonal(), rtol=1e-15)
    assert abs(A - A.T).max() == 0.0


@pytest.mark.parametrize("radius", [1.0, 2.5])
def test_sphere_spectrum_is_laplacian_shifted_by_two_over_r_squared(radius):
    # Measured discretisation error of the shift on the lowest 16 modes (l <= 3), relative
    # to 2/r^2: 6.5 % at 642 vertices, 1.53 % at 2562, 0.32 % at 10242 (O(h^2)).
    errors = []
    for subdivisions in (3, 4):
        mesh = icosphere(subdivisions, radius=radius)
        lap = mv.compute_spectrum(mesh, "laplacian", k=16).eigenvalues
        mod = mv.compute_spectrum(mesh, "modified_dirichlet", k=16).eigenvalues
        errors.append(np.max(np.abs((mod - lap) * radius**2 / 2.0 - 1.0)))
    assert errors[0] < 0.07
    assert errors[1] < 0.016
    assert errors[1] < errors[0] / 3.5  # converges like h^2


def test_sphere_laplacian_matches_analytic_eigenvalues():
    # l(l+1)/r^2 with multiplicity 2l+1; measured relative error 2.2 % at 2562 vertices.
    radius = 1.7
    mesh = icosphere(4, radius=radius)
    lam = mv.compute_spectrum(mesh, "laplacian", k=16).eigenvalues
    exact = np.repeat([0.0, 2.0, 6.0, 12.0], [1, 3, 5, 7]) / radius**2
    assert abs(lam[0]) < 1e-10
    np.testing.assert_allclose(lam[1:], exact[1:], rtol=0.023)
