"""Discrete curvature sqrt(k1^2 + k2^2) per vertex (for comparison with Fig. 8)."""

from __future__ import annotations

import numpy as np

from .laplacian import lumped_masses, stiffness_matrix
from .mesh import Mesh


def total_curvature(mesh: Mesh) -> np.ndarray:
    """(n,) sqrt(k1^2 + k2^2) = sqrt(4 H^2 - 2 K), units 1/length: H from the cotan
    mean-curvature normal ``|S x| / (2 m_i)``, K from the angle defect (pi - sum on the
    boundary) over the vertex mass."""
    v, f = mesh.vertices, mesh.faces
    m = lumped_masses(mesh)
    hn = stiffness_matrix(mesh) @ v
    mean = np.linalg.norm(hn, axis=1) / (2.0 * m)
    angles = np.zeros(mesh.n_vertices)
    for k in range(3):
        a = v[f[:, (k + 1) % 3]] - v[f[:, k]]
        b = v[f[:, (k + 2) % 3]] - v[f[:, k]]
        ang = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
        angles += np.bincount(f[:, k], ang, minlength=mesh.n_vertices)
    boundary = np.zeros(mesh.n_vertices, dtype=bool)
    boundary[mesh.edges[mesh.edge_face_counts == 1].ravel()] = True
    full = np.where(boundary, np.pi, 2 * np.pi)
    gauss = (full - angles) / m
    gauss[boundary] = 0.0  # the defect at a boundary is geodesic curvature, not K
    return np.sqrt(np.maximum(4.0 * mean**2 - 2.0 * gauss, 0.0))
