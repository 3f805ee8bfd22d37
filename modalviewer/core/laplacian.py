"""Cotan stiffness matrix, lumped mass matrix and vertex normals (paper Section 2).

Sign convention: ``S`` is positive semi-definite (the negative of libigl's
``cotmatrix``), ``S_ij = -(cot a_ij + cot b_ij) / 2`` and ``S_ii = -sum_j S_ij``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mesh import Mesh


def face_cotangents(mesh: Mesh) -> np.ndarray:
    """(m, 3) cotangent of the interior angle at corner k of each face."""
    v, f = mesh.vertices, mesh.faces
    cots = np.empty(f.shape, dtype=np.float64)
    twice_area = 2.0 * mesh.face_areas
    for k in range(3):
        a = v[f[:, (k + 1) % 3]] - v[f[:, k]]
        b = v[f[:, (k + 2) % 3]] - v[f[:, k]]
        cots[:, k] = np.einsum("ij,ij->i", a, b) / twice_area
    return cots


def stiffness_matrix(mesh: Mesh) -> sp.csr_matrix:
    """The (n, n) cotan stiffness matrix S (the Laplacian's energy ``f^T S f``), CSR,
    symmetric positive semi-definite, the constants in its null space; units of
    (length)^0.  Boundary edges get one cotangent term (natural / Neumann conditions)."""
    f = mesh.faces
    n = mesh.n_vertices
    cots = face_cotangents(mesh)
    # the angle at corner k is opposite the edge (k+1, k+2)
    i = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    j = np.concatenate([f[:, 2], f[:, 0], f[:, 1]])
    w = 0.5 * np.concatenate([cots[:, 0], cots[:, 1], cots[:, 2]])
    rows = np.concatenate([i, j, i, j])
    cols = np.concatenate([j, i, i, j])
    vals = np.concatenate([-w, -w, w, w])
    S = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    S.sum_duplicates()
    return S


def mass_matrix(mesh: Mesh) -> sp.dia_matrix:
    """The lumped (barycentric) mass matrix M, (n, n) DIA: ``m_i`` is a third of the
    area of the triangles around vertex i."""
    return sp.diags(lumped_masses(mesh), format="dia")


def lumped_masses(mesh: Mesh) -> np.ndarray:
    """(n,) vertex masses, one third of the summed area of the incident faces."""
    return np.bincount(
        mesh.faces.ravel(), np.repeat(mesh.face_areas / 3.0, 3), minlength=mesh.n_vertices
    )


def vertex_normals(mesh: Mesh, weighting: str = "area") -> np.ndarray:
    """(n, 3) unit vertex normals: ``weighting="area"`` sums the unnormalised face
    normals (area-weighted), ``"angle"`` weights unit face normals by the corner angle."""
    f = mesh.faces
    nt = mesh.face_normals_unnormalized
    if weighting == "area":
        w = np.repeat(nt, 3, axis=0)
    elif weighting == "angle":
        v = mesh.vertices
        unit = nt / np.linalg.norm(nt, axis=1, keepdims=True)
        ang = np.empty(f.shape)
        for k in range(3):
            a = v[f[:, (k + 1) % 3]] - v[f[:, k]]
            b = v[f[:, (k + 2) % 3]] - v[f[:, k]]
            ang[:, k] = np.arctan2(
                np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b)
            )
        w = (unit[:, None, :] * ang[:, :, None]).reshape(-1, 3)
    else:
        raise ValueError(f"weighting must be 'area' or 'angle', got {weighting!r}")
    normals = np.stack(
        [np.bincount(f.ravel(), w[:, c], minlength=mesh.n_vertices) for c in range(3)], axis=1
    )
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    length[length == 0] = 1.0
    return normals / length
