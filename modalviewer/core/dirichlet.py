"""Modified Dirichlet energy E_D^N (paper Section 3, eq. 12)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .laplacian import stiffness_matrix, vertex_normals
from .mesh import Mesh, MeshError

__all__ = ["modified_dirichlet_matrix"]


def modified_dirichlet_matrix(mesh: Mesh, normals: np.ndarray | None = None) -> sp.csr_matrix:
    """A, (n, n) symmetric PSD CSR with ``A_ij = <N_i, N_j> S_ij`` (so ``A_ii = S_ii``).

    ``normals`` defaults to the area-weighted unit vertex normals.  Requires a
    consistently oriented, edge-manifold mesh (normals are otherwise ambiguous).
    """
    problem = mesh.shell_problem()
    if problem:
        raise MeshError("E_D^N cannot run: " + problem)
    S = stiffness_matrix(mesh).tocoo()
    N = vertex_normals(mesh) if normals is None else np.asarray(normals, dtype=np.float64)
    dots = np.einsum("ij,ij->i", N[S.row], N[S.col])
    A = sp.csr_matrix((S.data * dots, (S.row, S.col)), shape=S.shape)
    return A
