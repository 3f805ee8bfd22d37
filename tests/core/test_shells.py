"""Discrete Shells: every gradient against finite differences, Lemma 1 against a full
finite-difference Hessian of the energy, rigid modes and invariance."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core import shells
from modalviewer.core.primitives import grid_plate, icosphere

RNG = np.random.default_rng(7)


def _fd_gradient(func, x, stencil, eps=1e-6):
    """Central differences of a per-element quantity: (e, L, 3)."""
    out = np.zeros(stencil.shape + (3,))
    for slot in range(stencil.shape[1]):
        for c in range(3):
            xp, xm = x.copy(), x.copy()
            # perturb the vertex in this slot for every element at once (stencils are
            # disjoint because each element gets its own vertices below)
            xp[stencil[:, slot], c] += eps
            xm[stencil[:, slot], c] -= eps
            out[:, slot, c] = (func(xp, stencil) - func(xm, stencil)) / (2 * eps)
    return out


def _disjoint(count, size):
    x = RNG.normal(size=(count * size, 3))
    return x, np.arange(count * size).reshape(count, size)


@pytest.mark.parametrize(
    "func,grad,size",
    [
        (shells.dihedral_angles, shells.dihedral_angle_gradients, 4),
        (shells.edge_lengths, shells.edge_length_gradients, 2),
        (shells.triangle_areas, shells.triangle_area_gradients, 3),
    ],
)
def test_gradients_against_finite_differences(func, grad, size):
    x, stencil = _disjoint(200, size)
    analytic = grad(x, stencil)
    numeric = _fd_gradient(func, x, stencil)
    np.testing.assert_allclose(analytic, numeric, rtol=1e-6, atol=1e-7)


def test_dihedral_angle_is_zero_when_flat_and_signed():
    x = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0]], dtype=float)
    h = np.array([[0, 1, 2, 3]])
    assert abs(shells.dihedral_angles(x, h)[0]) < 1e-15
    up, down = x.copy(), x.copy()
    up[3, 2], down[3, 2] = 0.3, -0.3
    a_up, a_down = shells.dihedral_angles(up, h)[0], shells.dihedral_angles(down, h)[0]
    assert a_up == pytest.approx(-a_down, rel=1e-14) and abs(a_up) > 0.1


def _fd_hessian_of_energy(mesh, bending, membrane, eps=1e-4):
    """Full Hessian by second differences of the scalar energy (independent of Lemma 1)."""
    x0 = mesh.vertices.ravel()
    n = x0.size

    def energy(x):  # E = sum over the terms of 1/2 w (f(x) - f(rest))^2 (shells' docstring)
        x = x.reshape(-1, 3)
        return sum(
            0.5 * float(np.sum(w * (f(x, stencil) - f(mesh.vertices, stencil)) ** 2))
            for stencil, f, _, w in shells._terms(mesh, bending, membrane)
        )

    H = np.zeros((n, n))
    for a in range(n):
        for b in range(a, n):
            ea = np.zeros(n)
            eb = np.zeros(n)
            ea[a] = eps
            eb[b] = eps
            val = (
                energy(x0 + ea + eb)
                - energy(x0 + ea - eb)
                - energy(x0 - ea + eb)
                + energy(x0 - ea - eb)
            ) / (4 * eps * eps)
            H[a, b] = H[b, a] = val
    return H


def _bumpy(mesh, amplitude, seed):
    rng = np.random.default_rng(seed)
    v = mesh.vertices + amplitude * rng.normal(size=mesh.vertices.shape)
    return mv.Mesh(v, mesh.faces)


@pytest.mark.parametrize(
    "mesh",
    [_bumpy(icosphere(0), 0.05, 1), _bumpy(grid_plate(3, 2), 0.05, 2)],
    ids=["closed", "open"],
)
@pytest.mark.parametrize("bending,membrane", [(1.0, 1.0), (0.3, 2.0)])
def test_lemma1_hessian_matches_full_hessian(mesh, bending, membrane):
    H = shells.shells_hessian(mesh, bending, membrane).toarray()
    H_fd = _fd_hessian_of_energy(mesh, bending, membrane)
    scale = np.abs(H).max()
    np.testing.assert_allclose(H, H_fd, atol=2e-6 * scale)
    np.testing.assert_allclose(H, H.T, atol=1e-14 * scale)


def test_closed_mesh_has_six_rigid_modes_with_gap(spot):
    spec = mv.compute_spectrum(spot, "shells", k=12)
    lam = spec.eigenvalues
    assert np.all(np.abs(lam[:6]) < 1e-8 * lam[-1])
    assert lam[6] > 1e6 * np.abs(lam[:6]).max()
    # rigid motions span the zero space: translations are Mass-orthogonal to modes 6+
    trans = np.zeros((spot.n_vertices, 3, 3))
    for c in range(3):
        trans[:, c, c] = 1.0
    flat = spec.modes.reshape(-1, spec.k)
    mass3 = np.repeat(spec.mass, 3)
    proj = trans.reshape(-1, 3).T @ (mass3[:, None] * flat)
    assert np.abs(proj[:, 6:]).max() < 1e-8


def test_shells_spectrum_invariant_under_rigid_motion(spot):
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array(
        [[1, 0, 0], [0, np.cos(0.3), -np.sin(0.3)], [0, np.sin(0.3), np.cos(0.3)]]
    )
    moved = mv.Mesh(spot.vertices @ R.T + np.array([3.0, -1.0, 2.0]), spot.faces)
    a = mv.compute_spectrum(spot, "shells", k=20).eigenvalues[6:]
    b = mv.compute_spectrum(moved, "shells", k=20).eigenvalues[6:]
    np.testing.assert_allclose(a, b, rtol=1e-8)


def test_normal_hessian_is_projection_of_full_hessian():
    mesh = _bumpy(icosphere(1), 0.03, 4)
    H = mv.shells_hessian(mesh).toarray()
    N = mv.vertex_normals(mesh)
    P = np.zeros((3 * mesh.n_vertices, mesh.n_vertices))
    for i in range(mesh.n_vertices):
        P[3 * i : 3 * i + 3, i] = N[i]
    np.testing.assert_allclose(
        mv.normal_shells_hessian(mesh).toarray(), P.T @ H @ P, atol=1e-12 * np.abs(H).max()
    )


def test_flat_plate_normal_modes_are_pure_bending():
    # On a flat plate, normal variations do not stretch to first order: H_N is the
    # bending part alone, so the membrane weight must not change it.
    mesh = grid_plate(6, 6)
    a = mv.normal_shells_hessian(mesh, bending=1.0, membrane=1.0)
    b = mv.normal_shells_hessian(mesh, bending=1.0, membrane=50.0)
    assert abs(a - b).max() < 1e-10 * abs(a).max()
