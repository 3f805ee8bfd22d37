"""Discrete Shells energy (Grinspun et al. 2003) and its Hessian at rest (paper Lemma 1).

Every term has the form ``1/2 * sum_i w_i (f_i(x) - f_i(xbar))^2`` with weights at rest:

- flexural E_F over interior edges: f = signed dihedral angle, w = 3 |e|^2 / A_e;
- stretching E_L over all edges: f = |e|, w = 1 / |e|;
- area E_A over faces: f = A_T, w = 1 / A_T;

E = bending * E_F + membrane * (E_L + E_A).  Lemma 1 gives the Hessian at rest as
``H = sum_i w_i grad f_i grad f_i^T = G^T G``, G holding the rows ``sqrt(w_i) grad f_i``;
it is assembled here as that sparse product, in vertex-major order (dof ``3 * i + c``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .laplacian import vertex_normals
from .mesh import Mesh, MeshError, triangle_areas
from .products import threaded_product


# ----------------------------------------------------------------- topology
def hinges(mesh: Mesh) -> np.ndarray:
    """(h, 4) interior-edge stencils ``[x0, x1, x2, x3]``: the edge x0 -> x1, triangles
    (x0, x1, x2) and (x1, x0, x3).  Requires an edge-manifold, consistently oriented mesh."""
    problem = mesh.shell_problem()
    if problem:
        raise MeshError("Discrete Shells cannot run: " + problem)
    f = mesh.faces
    edge_of_halfedge = mesh.face_edges.ravel()  # half-edge 3t+k: f[t,k] -> f[t,k+1]
    interior = np.flatnonzero(mesh.edge_face_counts == 2)
    order = np.argsort(edge_of_halfedge, kind="stable")
    starts = np.concatenate([[0], np.cumsum(mesh.edge_face_counts)])
    first = order[starts[interior]]
    second = order[starts[interior] + 1]
    t1, k1 = np.divmod(first, 3)
    t2, k2 = np.divmod(second, 3)
    x0 = f[t1, k1]
    x1 = f[t1, (k1 + 1) % 3]
    x2 = f[t1, (k1 + 2) % 3]
    x3 = f[t2, (k2 + 2) % 3]
    assert np.all(f[t2, k2] == x1)
    return np.stack([x0, x1, x2, x3], axis=1)


# ------------------------------------------------------- elementary quantities
def _rows_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def dihedral_angles(x: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    """(h,) signed dihedral angles in radians (0 for a flat hinge, via atan2); the sign
    convention does not matter for the Hessian at rest."""
    x0, x1, x2, x3 = (x[hinge[:, k]] for k in range(4))
    e = x1 - x0
    n1 = np.cross(e, x2 - x0)
    n2 = np.cross(x0 - x1, x3 - x1)
    e_hat = e / np.linalg.norm(e, axis=1, keepdims=True)
    return np.arctan2(_rows_dot(np.cross(n1, n2), e_hat), _rows_dot(n1, n2))


def dihedral_angle_gradients(x: np.ndarray, hinge: np.ndarray) -> np.ndarray:
    """(h, 4, 3) gradient of :func:`dihedral_angles` w.r.t. x0, x1, x2, x3."""
    x0, x1, x2, x3 = (x[hinge[:, k]] for k in range(4))
    e = x1 - x0
    length = np.linalg.norm(e, axis=1)
    e_hat = e / length[:, None]
    n1 = np.cross(e, x2 - x0)
    n2 = np.cross(x0 - x1, x3 - x1)
    a1 = n1 / _rows_dot(n1, n1)[:, None]  # n1 / |n1|^2
    a2 = n2 / _rows_dot(n2, n2)[:, None]
    g = np.empty((len(hinge), 4, 3))
    g[:, 2] = -length[:, None] * a1
    g[:, 3] = -length[:, None] * a2
    g[:, 0] = -(_rows_dot(x2 - x1, e_hat)[:, None] * a1 + _rows_dot(x3 - x1, e_hat)[:, None] * a2)
    g[:, 1] = _rows_dot(x2 - x0, e_hat)[:, None] * a1 + _rows_dot(x3 - x0, e_hat)[:, None] * a2
    return g


def edge_lengths(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) edge lengths."""
    return np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)


def edge_length_gradients(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E, 2, 3) gradient of the edge length w.r.t. its two end points."""
    d = x[edges[:, 1]] - x[edges[:, 0]]
    u = d / np.linalg.norm(d, axis=1, keepdims=True)
    return np.stack([-u, u], axis=1)


def triangle_area_gradients(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3, 3) gradient of the area w.r.t. corner k: 1/2 n_hat x (x_{k+2} - x_{k+1})."""
    p = [x[faces[:, k]] for k in range(3)]
    n = np.cross(p[1] - p[0], p[2] - p[0])
    n_hat = n / np.linalg.norm(n, axis=1, keepdims=True)
    return np.stack(
        [0.5 * np.cross(n_hat, p[(k + 2) % 3] - p[(k + 1) % 3]) for k in range(3)], axis=1
    )


# --------------------------------------------------------------- the energy
def _terms(mesh: Mesh, bending: float, membrane: float):
    """Per term: (stencil (e, L), f(x) callable, grad callable, weights at rest (e,))."""
    rest = mesh.vertices
    hinge = hinges(mesh)
    edges = mesh.edges
    if bending:
        # combined area A_e of the two triangles of each hinge
        a_e = triangle_areas(rest, hinge[:, [0, 1, 2]]) + triangle_areas(rest, hinge[:, [1, 0, 3]])
        len_e = edge_lengths(rest, hinge[:, :2])
        yield hinge, dihedral_angles, dihedral_angle_gradients, bending * 3.0 * len_e**2 / a_e
    if membrane:
        yield edges, edge_lengths, edge_length_gradients, membrane / edge_lengths(rest, edges)
        yield mesh.faces, triangle_areas, triangle_area_gradients, membrane / mesh.face_areas


def weighted_gradient_matrix(
    mesh: Mesh,
    bending: float = 1.0,
    membrane: float = 1.0,
    normals: np.ndarray | None = None,
) -> sp.csr_matrix:
    """G with one row ``sqrt(w_i) grad f_i^T`` per term of non-zero weight (interior
    edges, edges, faces, in that order), so that the Hessian at rest is ``G^T G``
    (Lemma 1).  Columns: the 3n vertex-major dofs, or with ``normals`` (n, 3) the n
    normal variations, which gives ``H_N = G_N^T G_N`` without the 3n Hessian."""
    for name, value in (("bending", bending), ("membrane", membrane)):
        if not np.isfinite(value) or value < 0:
            raise ValueError(f"{name} weight must be a finite number >= 0, got {value}")
    if bending == 0 and membrane == 0:
        raise ValueError("bending and membrane weights cannot both be zero")
    n = mesh.n_vertices if normals is not None else 3 * mesh.n_vertices
    blocks = []
    for stencil, _, df, w in _terms(mesh, bending, membrane):
        e, L = stencil.shape
        g = df(mesh.vertices, stencil) * np.sqrt(w)[:, None, None]  # (e, L, 3)
        if normals is None:
            cols = (3 * stencil[:, :, None] + np.arange(3)).reshape(e, 3 * L)
            vals = g.reshape(e, 3 * L)
        else:
            cols = stencil
            vals = np.einsum("elc,elc->el", g, normals[stencil])
        indptr = np.arange(0, vals.size + 1, cols.shape[1], dtype=np.int64)
        blocks.append(sp.csr_matrix((vals.ravel(), cols.ravel(), indptr), shape=(e, n)))
    return sp.vstack(blocks, format="csr")


def _gram(G: sp.csr_matrix) -> sp.csr_matrix:
    """``G^T G`` as a symmetric CSR with sorted indices."""
    A = threaded_product(G.T.tocsr(), G)
    A.sort_indices()
    return A


def shells_hessian(mesh: Mesh, bending: float = 1.0, membrane: float = 1.0) -> sp.csr_matrix:
    """The Hessian H of the Discrete Shells energy at rest (Lemma 1) as ``G^T G``: (3n, 3n)
    CSR, symmetric positive semi-definite, the rigid motions in its null space, mass
    ``kron(M, I3)``.  Bending scales like 1 / length^2 and membrane like 1 / length, so
    the spectrum depends on the mesh's absolute size."""
    return _gram(weighted_gradient_matrix(mesh, bending, membrane))


def normal_shells_hessian(mesh: Mesh, bending: float = 1.0, membrane: float = 1.0) -> sp.csr_matrix:
    """``H_N = P^T H P``: the shells Hessian restricted to normal variations ``f N`` (P
    (3n, n) holding the unit vertex normals), assembled as ``(G P)^T (G P)``; (n, n) CSR,
    symmetric positive semi-definite."""
    return _gram(weighted_gradient_matrix(mesh, bending, membrane, normals=vertex_normals(mesh)))
