"""Stiffness, mass and normals: hand values, an independent assembly, identities."""

import numpy as np
import pytest
import scipy.sparse as sp

import modalviewer as mv
from modalviewer.core.primitives import grid_plate, icosphere


def test_right_triangle_hand_values():
    mesh = mv.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    S = mv.stiffness_matrix(mesh).toarray()
    # angles 90, 45, 45 degrees: cot = 0, 1, 1
    expected = np.array([[1.0, -0.5, -0.5], [-0.5, 0.5, 0.0], [-0.5, 0.0, 0.5]])
    np.testing.assert_allclose(S, expected, atol=1e-15)
    M = mv.mass_matrix(mesh).toarray()
    np.testing.assert_allclose(M, np.eye(3) / 6.0, atol=1e-15)


def test_equilateral_triangle_hand_values():
    h = np.sqrt(3) / 2
    mesh = mv.Mesh([[0, 0, 0], [1, 0, 0], [0.5, h, 0]], [[0, 1, 2]])
    S = mv.stiffness_matrix(mesh).toarray()
    c = 1 / np.sqrt(3)  # cot 60
    expected = np.full((3, 3), -c / 2)
    np.fill_diagonal(expected, c)
    np.testing.assert_allclose(S, expected, atol=1e-15)
    np.testing.assert_allclose(mv.mass_matrix(mesh).diagonal(), np.full(3, h / 2 / 3), atol=1e-15)


def _stiffness_by_gradients(mesh):
    """Independent assembly: S = sum_T A_T G_T^T G_T with hat-function gradients G_T."""
    v, f = mesh.vertices, mesh.faces
    n = mesh.n_vertices
    rows, cols, vals = [], [], []
    for t in range(len(f)):
        p = v[f[t]]
        e1, e2 = p[1] - p[0], p[2] - p[0]
        normal = np.cross(e1, e2)
        area = np.linalg.norm(normal) / 2
        nh = normal / np.linalg.norm(normal)
        grads = np.array([np.cross(nh, p[(k + 2) % 3] - p[(k + 1) % 3]) for k in range(3)])
        grads /= 2 * area
        local = area * grads @ grads.T
        for a in range(3):
            for b in range(3):
                rows.append(f[t, a])
                cols.append(f[t, b])
                vals.append(local[a, b])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n)).toarray()


def test_stiffness_matches_independent_assembly_on_real_mesh(spot):
    S = mv.stiffness_matrix(spot)
    reference = _stiffness_by_gradients(spot)
    np.testing.assert_allclose(S.toarray(), reference, atol=1e-12 * np.abs(reference).max())


def test_stiffness_symmetric_psd_constants_in_kernel(spot):
    S = mv.stiffness_matrix(spot)
    assert abs(S - S.T).max() == 0.0
    np.testing.assert_allclose(S @ np.ones(spot.n_vertices), 0.0, atol=1e-12)
    lam = np.linalg.eigvalsh(S.toarray())
    assert lam.min() > -1e-10 * lam.max()


def test_dirichlet_energy_of_linear_function_on_plate():
    mesh = grid_plate(7, 5, width=2.0, height=1.5)
    S = mv.stiffness_matrix(mesh)
    a = np.array([0.3, -1.2])
    u = mesh.vertices[:, :2] @ a
    # for a linear function the discrete Dirichlet energy is exact: |grad u|^2 * area
    assert u @ S @ u == pytest.approx(a @ a * 3.0, rel=1e-12)


def test_mass_sums_to_area_and_normals_on_sphere():
    mesh = icosphere(3, radius=2.0)
    assert mv.mass_matrix(mesh).diagonal().sum() == pytest.approx(mesh.total_area, rel=1e-14)
    for weighting in ("area", "angle"):
        N = mv.vertex_normals(mesh, weighting=weighting)
        radial = mesh.vertices / np.linalg.norm(mesh.vertices, axis=1, keepdims=True)
        np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-14)
        assert np.min(np.einsum("ij,ij->i", N, radial)) > 0.999
