"""Modified Dirichlet energy E_D^N (paper Section 3, eq. 12)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .laplacian import stiffness_matrix, vertex_normals
from .mesh import Mesh, MeshError


def modified_dirichlet_matrix(mesh: Mesh, normals: np.ndarray | None = None) -> sp.csr_matrix:
    """The matrix A of the modified Dirichlet energy E_D^N, ``A_ij = <N_i, N_j> S_ij`` (so
    ``A_ii = S_ii``), with S the cotan stiffness matrix and N the unit vertex
    ``normals`` (default: :func:`.laplacian.vertex_normals`); CSR, symmetric positive
    semi-definite.  A MeshError unless the mesh is consistently oriented and
    edge-manifold (the normals are otherwise ambiguous)."""
    problem = mesh.shell_problem()
    if problem:
        raise MeshError("E_D^N cannot run: " + problem)
    S = stiffness_matrix(mesh).tocoo()
    N = vertex_normals(mesh) if normals is None else np.asarray(normals, dtype=np.float64)
    dots = np.einsum("ij,ij->i", N[S.row], N[S.col])
    return sp.csr_matrix((S.data * dots, (S.row, S.col)), shape=S.shape)
