"""The robust Laplacian: the intrinsic Delaunay Laplacian of the tufted cover (Sharp and
Crane, SGP 2020), from the optional ``robust-laplacian`` package.

Obtuse and sliver triangles make cotan weights negative (signatures can oscillate); the
intrinsic Delaunay weights are non-negative, and the tufted cover accepts non-manifold
meshes.
"""

from __future__ import annotations

import weakref

import numpy as np
import scipy.sparse as sp

from ..extras import extra_needed
from .laplacian import face_cotangents
from .mesh import Mesh


def robust_laplacian_matrices(mesh: Mesh) -> tuple[sp.csr_matrix, np.ndarray]:
    """(L, m): the intrinsic Delaunay stiffness matrix and the (n,) lumped masses of
    ``robust_laplacian.mesh_laplacian`` (default mollification); a
    :class:`MissingExtraError` without ``pip install "modalviewer[robust]"``."""
    with extra_needed("the operator laplacian_robust"):
        import robust_laplacian
    L, M = robust_laplacian.mesh_laplacian(
        np.ascontiguousarray(mesh.vertices, dtype=np.float64),
        np.ascontiguousarray(mesh.faces, dtype=np.int64),
    )
    return sp.csr_matrix(L), np.asarray(M.diagonal(), dtype=np.float64)


_COUNTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def negative_cotan_weights(mesh: Mesh) -> int:
    """The number of edges whose cotan weight ``(cot alpha + cot beta) / 2`` is negative
    beyond round-off (1e-12 of the largest), counted without assembling the matrix and
    kept per mesh object, so the window counts while reading and asks again for free."""
    if mesh in _COUNTS:
        return _COUNTS[mesh]
    cots = face_cotangents(mesh)
    # face_edges[:, k] runs from corner k to k + 1: the angle opposite it is at k + 2
    opposite = cots[:, [2, 0, 1]]
    w = 0.5 * np.bincount(mesh.face_edges.ravel(), opposite.ravel(), minlength=len(mesh.edges))
    _COUNTS[mesh] = int(np.count_nonzero(w < -1e-12 * float(np.abs(w).max())))
    return _COUNTS[mesh]
