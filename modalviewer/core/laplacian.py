"""Cotan stiffness matrix, lumped mass matrix and vertex normals (paper Section 2), and
what is made of them: the modified Dirichlet energy E_D^N (Section 3) and the discrete
curvature of Fig. 8.

Sign convention: ``S`` is positive semi-definite (the negative of libigl's
``cotmatrix``), ``S_ij = -(cot a_ij + cot b_ij) / 2`` and ``S_ii = -sum_j S_ij``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mesh import Mesh, MeshError


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
        unit = nt / np.linalg.norm(nt, axis=1, keepdims=True)
        w = (unit[:, None, :] * corner_angles(mesh)[:, :, None]).reshape(-1, 3)
    else:
        raise ValueError(f"weighting must be 'area' or 'angle', got {weighting!r}")
    normals = np.stack(
        [np.bincount(f.ravel(), w[:, c], minlength=mesh.n_vertices) for c in range(3)], axis=1
    )
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    length[length == 0] = 1.0
    return normals / length


def corner_angles(mesh: Mesh) -> np.ndarray:
    """(m, 3) interior angle at corner k of each face."""
    v, f = mesh.vertices, mesh.faces
    angles = np.empty(f.shape)
    for k in range(3):
        a = v[f[:, (k + 1) % 3]] - v[f[:, k]]
        b = v[f[:, (k + 2) % 3]] - v[f[:, k]]
        angles[:, k] = np.arctan2(
            np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b)
        )
    return angles


def modified_dirichlet_matrix(mesh: Mesh, normals: np.ndarray | None = None) -> sp.csr_matrix:
    """The matrix A of the modified Dirichlet energy E_D^N, ``A_ij = <N_i, N_j> S_ij`` (so
    ``A_ii = S_ii``), with S the cotan stiffness matrix and N the unit vertex
    ``normals`` (default: :func:`vertex_normals`); CSR, symmetric positive
    semi-definite.  A MeshError unless the mesh is consistently oriented and
    edge-manifold (the normals are otherwise ambiguous)."""
    problem = mesh.shell_problem()
    if problem:
        raise MeshError("E_D^N cannot run: " + problem)
    S = stiffness_matrix(mesh).tocoo()
    N = vertex_normals(mesh) if normals is None else np.asarray(normals, dtype=np.float64)
    dots = np.einsum("ij,ij->i", N[S.row], N[S.col])
    return sp.csr_matrix((S.data * dots, (S.row, S.col)), shape=S.shape)


def total_curvature(mesh: Mesh) -> np.ndarray:
    """(n,) sqrt(k1^2 + k2^2) = sqrt(4 H^2 - 2 K), units 1/length (for comparison with
    Fig. 8): H from the cotan mean-curvature normal ``|S x| / (2 m_i)``, K from the angle
    defect (pi - sum on the boundary) over the vertex mass."""
    n = mesh.n_vertices
    m = lumped_masses(mesh)
    mean = np.linalg.norm(stiffness_matrix(mesh) @ mesh.vertices, axis=1) / (2.0 * m)
    angles = np.bincount(mesh.faces.ravel(), corner_angles(mesh).ravel(), minlength=n)
    boundary = np.zeros(n, dtype=bool)
    boundary[mesh.edges[mesh.edge_face_counts == 1].ravel()] = True
    gauss = (np.where(boundary, np.pi, 2 * np.pi) - angles) / m
    gauss[boundary] = 0.0  # the defect at a boundary is geodesic curvature, not K
    return np.sqrt(np.maximum(4.0 * mean**2 - 2.0 * gauss, 0.0))
