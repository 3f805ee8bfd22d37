"""The scalar that colours a mode: the mode itself for scalar operators; for 3D vibration
modes its magnitude or its normal component against *smoothed* normals (plain normals
jump across a sharp edge and make jagged isolines; the component stays signed, so its
zero line shows where the surface does not move along its normal).  The viewer guide,
"How the pictures are drawn", compares them.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..core.factor import SPDSolver
from ..core.laplacian import lumped_masses, stiffness_matrix, vertex_normals
from ..core.mesh import Mesh

NORMAL_SMOOTHING = 2.0  # diffusion radius in mean edge lengths


def mean_edge_length(mesh: Mesh) -> float:
    v, f = mesh.vertices, mesh.faces
    e = np.concatenate([v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 1]], v[f[:, 0]] - v[f[:, 2]]])
    return float(np.mean(np.linalg.norm(e, axis=1)))


def smoothed_normals(mesh: Mesh, radius: float | None = None) -> np.ndarray:
    """(n, 3) unit normals after one implicit heat step (M + r^2 S) N' = M N (``radius``
    r default: ``NORMAL_SMOOTHING`` mean edge lengths); a vanishing one stays plain."""
    normals = vertex_normals(mesh)
    r = NORMAL_SMOOTHING * mean_edge_length(mesh) if radius is None else float(radius)
    if r <= 0:
        return normals
    m = lumped_masses(mesh)
    # symmetric positive definite: a Cholesky factorisation (PARDISO where available),
    # fast enough for the GUI thread on scanned meshes, unlike SuperLU's LU
    system = sp.diags(m) + r * r * stiffness_matrix(mesh)
    smooth = SPDSolver(system).solve(m[:, None] * normals)
    norm = np.linalg.norm(smooth, axis=1, keepdims=True)
    ok = norm[:, 0] > 1e-12
    out = normals.copy()
    out[ok] = smooth[ok] / norm[ok]
    return out


def vector_mode_scalar(phi: np.ndarray, normals: np.ndarray, coloring: str = "normal"):
    """A 3D mode ``phi`` (n, 3) as a scalar: "normal" (phi . normals) or "magnitude"."""
    phi = np.asarray(phi, dtype=np.float64)
    if coloring == "normal":
        return np.einsum("ij,ij->i", phi, normals)
    if coloring == "magnitude":
        return np.linalg.norm(phi, axis=1)
    raise ValueError(f"unknown colouring {coloring!r}; use 'normal' or 'magnitude'")


def mode_scalar(spec, j: int, normals: np.ndarray, coloring: str = "normal") -> np.ndarray:
    """Mode ``j`` of ``spec`` as a scalar (:func:`vector_mode_scalar` for 3D modes)."""
    phi = spec.mode(j)
    return vector_mode_scalar(phi, normals, coloring) if spec.is_vector else np.asarray(phi)
