"""Reduced spaces of smooth, locally supported functions on a mesh: the space of the
preview spectra (:mod:`.preview`).

After Nasikun, Brandt, Hildebrandt: *Fast Approximation of Laplace-Beltrami
Eigenproblems*, SGP 2018:

- ``m`` well-spread vertices are chosen by farthest-point sampling;
- around each sample c_i a compactly supported Wendland function
  ``psi_i = (1 - d/r)^4 (4 d/r + 1)`` of the Euclidean distance d, radius r a few sample
  spacings; where the ball reaches parts of the surface far from c_i along the
  surface, only on the vertices connected to c_i inside the ball (parts that touch in
  space, such as a tail against a leg, share no function);
  ``phi_i = psi_i / sum_j psi_j`` is a partition of unity;
- each ``phi_i`` is enriched by ``phi_i * <x - c_i, t>/r`` for the two unit tangents t of
  the surface at c_i (locally linear functions, Nasikun et al.'s linear enrichment in the
  tangent plane, where the normal coordinate would be nearly linearly dependent on flat
  parts), and optionally by ``phi_i u^2, phi_i uv, phi_i v^2`` (u, v those tangent
  coordinates): a bending energy measures second derivatives, which a partition of unity
  times linear functions does not approximate.

The columns of the prolongation P (:class:`ReducedBasis`) hold these functions.  For the
Discrete Shells the space is vector valued: every scalar function times e_x, e_y, e_z,
plus the three linearised rotations ``e_a x (x - centroid)`` as global functions, so the
six rigid motions are in the space exactly (translations come from the partition of
unity).  For the normal-restricted shells the scalar functions multiply the vertex
normals, which is the scalar problem of ``H_N``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .laplacian import vertex_normals
from .mesh import Mesh
from .operators import RADIUS_FACTOR, operator_info
from .products import csr_rows, row_blocks, threaded_product, threaded_transpose_product

__all__ = [
    "DEFAULT_SAMPLES",
    "RADIUS_FACTOR",
    "farthest_point_samples",
    "partition_of_unity_basis",
    "rotation_fields",
    "ReducedBasis",
    "reduced_basis",
    "scalar_functions_per_sample",
    "max_samples",
]

DEFAULT_SAMPLES = 200
"""Samples (centres of basis functions) of :func:`reduced_basis` when none are given;
:func:`.preview.preview_spectrum` takes its own per operator from
:attr:`.operators.OperatorInfo.preview`."""


def farthest_point_samples(
    points: np.ndarray, m: int, candidates: int | None = None, seed: int = 0
) -> np.ndarray:
    """Indices of ``m`` well-spread points (Euclidean farthest-point sampling).

    The sampling runs over ``candidates`` points drawn at random (default ``8 m``, all
    points if fewer), which costs O(m * candidates) instead of O(m * n) and spreads the
    samples as evenly as candidates that dense allow.  Deterministic for a given seed.
    """
    n = len(points)
    m = int(min(max(m, 1), n))
    c = n if candidates is None else int(candidates)
    c = min(n, max(c if candidates is not None else 8 * m, m))
    rng = np.random.default_rng(seed)
    idx = np.sort(rng.choice(n, c, replace=False)) if c < n else np.arange(n)
    pts = np.ascontiguousarray(points[idx])
    # start from the point farthest from the centroid
    current = int(np.argmax(((pts - pts.mean(axis=0)) ** 2).sum(axis=1)))
    dist = np.full(c, np.inf)
    chosen = np.empty(m, dtype=np.int64)
    for j in range(m):
        chosen[j] = current
        diff = pts - pts[current]
        np.minimum(dist, np.einsum("ij,ij->i", diff, diff), out=dist)
        current = int(np.argmax(dist))
    return idx[chosen]


def _tangents(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents per unit normal, orthogonal to it and to each other."""
    helper = np.zeros_like(normals)
    along_x = np.abs(normals[:, 0]) < 0.9
    helper[along_x, 0] = 1.0
    helper[~along_x, 1] = 1.0
    t1 = np.cross(normals, helper)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, np.cross(normals, t1)


PATH_FACTOR = 1.5
"""A ball is searched for parts far from its centre along the surface (see
:func:`_near_along_surface`) when the path through the cells to one of its vertices is
longer than this many times the straight distance plus the covering radius."""


def _surface_graph(mesh: Mesh) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray, np.ndarray]:
    """The mesh's edge graph with parts that meet only at vertices kept apart.

    Returns (graph, tails, heads, vertex_of): a sparse (N, N) matrix of edge lengths
    over graph nodes, the nodes of every half-edge, and each node's vertex.  A vertex is
    one node, except where parts whose faces are not connected through edges
    (:attr:`.Mesh.n_face_components`) meet at it: there it is one node per part, so no
    path passes from one part to the other through that vertex.
    """
    n, f = mesh.n_vertices, mesh.faces
    corner_vertex = f.ravel()
    node = corner_vertex
    if mesh.n_face_components > mesh.n_components:
        part = np.repeat(mesh.face_component_labels, 3)
        lowest = np.full(n, np.iinfo(np.int64).max)
        highest = np.full(n, -1)
        np.minimum.at(lowest, corner_vertex, part)
        np.maximum.at(highest, corner_vertex, part)
        split = (lowest != highest)[corner_vertex]
        key = corner_vertex[split] * (int(part.max()) + 1) + part[split]
        node = corner_vertex.copy()
        node[split] = n + np.unique(key, return_inverse=True)[1]
    n_nodes = int(node.max(initial=n - 1)) + 1
    heads = node.reshape(-1, 3)[:, [1, 2, 0]].ravel()
    vertex_of = np.full(n_nodes, -1, dtype=np.int64)  # -1: a vertex split into parts
    vertex_of[node] = corner_vertex
    x = mesh.vertices
    lengths = np.linalg.norm(x[vertex_of[heads]] - x[vertex_of[node]], axis=1)
    # every half-edge once; an undirected search walks each edge either way
    graph = sp.csr_matrix((lengths, (node, heads)), shape=(n_nodes, n_nodes))
    return graph, node, heads, vertex_of


def _near_along_surface(
    mesh: Mesh,
    centers: np.ndarray,
    ci: np.ndarray,
    vi: np.ndarray,
    straight: np.ndarray,
    cover: float,
) -> np.ndarray:
    """Which (centre, vertex) pairs of the balls to keep: in a ball that reaches parts of
    the surface far from its centre along the surface, only the vertices connected to the
    centre through edges inside the ball.

    Parts that touch in space but not along the surface (a thin part lying against
    another) then share no function, which would couple them.  The cut runs at the ball's
    boundary, where the function vanishes anyway, so the functions stay as smooth as the
    balls'.  Only the balls a cheap test flags are searched: every vertex belongs to the
    cell of the centre nearest to it along the edges (one multi-source Dijkstra run over
    :func:`_surface_graph`), the distance between two cells is the shortest path through
    neighbouring centres, and a ball is searched when that distance from the centre's
    cell to one of its vertices' cells is more than :data:`PATH_FACTOR` times their
    straight distance plus ``cover``.  Parts that meet only at a vertex are apart in the
    graph; that vertex belongs to both.  A vertex that would lose every function keeps
    its pairs.  Costs and the tests: "Supports cut along the surface" in
    docs/how-it-works.md.

    Parameters
    ----------
    mesh : Mesh
        The surface.
    centers : ndarray of int, shape (m,)
        The sample vertices, the balls' centres.
    ci, vi : ndarray of int, shape (P,)
        Each pair's centre (an index into ``centers``) and vertex.
    straight : ndarray of float, shape (P,)
        The pairs' distances in space.
    cover : float
        The covering radius of the samples.

    Returns
    -------
    ndarray of bool, shape (P,)
        True for the pairs to keep.
    """
    from scipy.sparse.csgraph import dijkstra

    n, m = mesh.n_vertices, len(centers)
    graph, tails, heads, vertex_of = _surface_graph(mesh)
    # one cell per source node: a centre where parts meet has one cell in each part
    sources = np.flatnonzero(np.isin(vertex_of, centers))
    n_cells = len(sources)
    nearest = dijkstra(
        graph, directed=False, indices=sources, min_only=True, return_predecessors=True
    )[2]
    cell_of_node = np.full(len(vertex_of), -1, dtype=np.int64)
    cell_of_node[sources] = np.arange(n_cells)
    cell = np.where(nearest >= 0, cell_of_node[np.maximum(nearest, 0)], -1)
    a, b = cell[tails], cell[heads]
    across = (a != b) & (a >= 0) & (b >= 0)
    pair = np.unique(np.minimum(a[across], b[across]) * n_cells + np.maximum(a[across], b[across]))
    first, second = pair // n_cells, pair % n_cells
    position = mesh.vertices[vertex_of[sources]]
    steps = sp.csr_matrix(
        (np.linalg.norm(position[first] - position[second], axis=1), (first, second)),
        shape=(n_cells, n_cells),
    )
    slot = np.full(n, -1, dtype=np.int64)
    slot[centers] = np.arange(m)
    between = np.full((m, n_cells), np.inf)  # from each centre's nearest own cell
    np.minimum.at(between, slot[vertex_of[sources]], dijkstra(steps, directed=False))
    # nodes below n are the vertices; one split into parts is in no cell
    vertex_cell = cell[:n][vi]
    inside = vertex_cell >= 0
    near = ~inside
    near[inside] = between[ci[inside], vertex_cell[inside]] <= PATH_FACTOR * (
        straight[inside] + cover
    )
    keep = np.ones(len(ci), dtype=bool)
    for ball in np.unique(ci[~near]):
        pairs = np.flatnonzero(ci == ball)
        keep[pairs] = _connected_in_ball(graph, vertex_of, vi[pairs], centers[ball], n)
    covered = np.zeros(n, dtype=bool)
    covered[vi[keep]] = True
    keep |= ~covered[vi]
    return keep


def _connected_in_ball(
    graph: sp.csr_matrix, vertex_of: np.ndarray, ball_vertices: np.ndarray, center: int, n: int
) -> np.ndarray:
    """Mask of ``ball_vertices`` connected to ``center`` through edges of ``graph``
    (:func:`_surface_graph`, over a mesh of ``n`` vertices) between the ball's vertices."""
    from scipy.sparse.csgraph import connected_components

    in_ball = np.zeros(n, dtype=bool)
    in_ball[ball_vertices] = True
    nodes = np.flatnonzero((vertex_of >= 0) & in_ball[np.maximum(vertex_of, 0)])
    labels = connected_components(graph[nodes][:, nodes], directed=False)[1]
    reached = np.zeros(n, dtype=bool)
    reached[vertex_of[nodes[np.isin(labels, labels[vertex_of[nodes] == center])]]] = True
    return reached[ball_vertices]


def partition_of_unity_basis(
    mesh: Mesh,
    centers: np.ndarray,
    radius_factor: float = RADIUS_FACTOR,
    enrich: int = 1,
    normals: np.ndarray | None = None,
) -> tuple[sp.csr_matrix, float]:
    """Scalar reduced basis P, (n, q * len(centers)), and the support radius r.

    Column ``q * i`` is the partition-of-unity function phi_i of centre ``centers[i]``;
    with ``enrich`` (q = 3) columns ``q * i + 1`` and ``q * i + 2`` are
    ``phi_i * <x - c_i, t>/r`` for the two unit tangents t at c_i.  Rows sum to 1 over the
    columns ``q * i`` (so constants are reproduced exactly).
    """
    x = mesh.vertices
    c = x[np.asarray(centers, dtype=np.int64)]
    tree_c = cKDTree(c)
    nearest, _ = tree_c.query(x)
    h = float(np.max(nearest))
    if h <= 0:
        h = float(np.max(np.ptp(x, axis=0))) or 1.0
    r = radius_factor * h
    pairs = tree_c.sparse_distance_matrix(cKDTree(x), r, output_type="ndarray")
    ci = pairs["i"].astype(np.int64)
    vi = pairs["j"].astype(np.int64)
    s = pairs["v"] / r
    del pairs
    # the centre's own vertex is at distance 0, which sparse_distance_matrix may leave out
    own = np.asarray(centers, dtype=np.int64)
    have = np.zeros(len(own), dtype=bool)
    have[ci[vi == own[ci]]] = True
    missing = np.flatnonzero(~have)
    if missing.size:
        ci = np.concatenate([ci, missing])
        vi = np.concatenate([vi, own[missing]])
        s = np.concatenate([s, np.zeros(len(missing))])
    keep = _near_along_surface(mesh, own, ci, vi, s * r, h)
    if not keep.all():
        ci, vi, s = ci[keep], vi[keep], s[keep]
    del keep
    n, m = mesh.n_vertices, len(own)
    psi = (1.0 - s) ** 4 * (4.0 * s + 1.0)
    del s
    phi = psi / np.bincount(vi, psi, minlength=n)[vi]
    del psi
    # CSR directly, rows in vertex order: no COO triplets (a third more memory than the
    # matrix, and a copy to convert), the q values of a pair side by side
    counts = np.bincount(vi, minlength=n)
    order = np.argsort(vi, kind="stable")
    ci, vi, phi = ci[order], vi[order], phi[order]
    del order
    q = 1 if not enrich else (6 if int(enrich) >= 2 else 3)
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts * q, out=indptr[1:])
    index_type = np.int32 if q * m < 2**31 else np.int64
    indices = np.empty((len(ci), q), dtype=index_type)
    for j in range(q):
        indices[:, j] = q * ci + j
    data = np.empty((len(ci), q))
    data[:, 0] = phi
    if enrich:
        if normals is None:
            normals = vertex_normals(mesh)
        t1, t2 = _tangents(normals[own])
        for start in range(0, len(ci), PAIR_CHUNK):  # (pairs, 3) temporaries stay small
            rows = slice(start, start + PAIR_CHUNK)
            rel = (x[vi[rows]] - c[ci[rows]]) / r
            u = np.einsum("ij,ij->i", rel, t1[ci[rows]])
            v = np.einsum("ij,ij->i", rel, t2[ci[rows]])
            data[rows, 1] = phi[rows] * u
            data[rows, 2] = phi[rows] * v
            if q == 6:
                data[rows, 3] = phi[rows] * u * u
                data[rows, 4] = phi[rows] * u * v
                data[rows, 5] = phi[rows] * v * v
    del ci, vi, phi
    P = sp.csr_matrix((data.reshape(-1), indices.reshape(-1), indptr), shape=(n, q * m))
    if not P.has_sorted_indices:
        P.sort_indices()  # in place
    return P, r


PAIR_CHUNK = 1 << 18
"""(centre, vertex) pairs per chunk of the tangent coordinates in
:func:`partition_of_unity_basis`."""


def rotation_fields(mesh: Mesh) -> np.ndarray:
    """(3n, 3) linearised rotations ``e_a x (x - centroid)``, vertex-major, unit-scaled."""
    x = mesh.vertices - mesh.vertices.mean(axis=0)
    R = np.empty((mesh.n_vertices, 3, 3))
    for a in range(3):
        e = np.zeros(3)
        e[a] = 1.0
        R[:, :, a] = np.cross(e, x)
    R = R.reshape(-1, 3)
    return R / np.linalg.norm(R, axis=0, keepdims=True)


@dataclass
class ReducedBasis:
    """The prolongation ``P = [kron(scalar, I_c)  dense]`` of a reduced space.

    ``scalar`` (n, q) holds the scalar functions on the vertices.  With ``components``
    3 (Discrete Shells) every one of them times e_x, e_y, e_z is a column: unknowns are
    vertex-major (row 3 v + a), column 3 j + a is scalar function j times e_a.  The
    Kronecker product is never formed: products with P go through the scalar matrix
    (a third of the entries and of the work).  ``dense`` (c n, d) holds global columns
    (the shells' rotations, exact null vectors the space lacks) or is None.
    """

    scalar: sp.csr_matrix
    components: int
    dense: np.ndarray | None
    info: dict

    @property
    def n_sparse(self) -> int:
        return self.scalar.shape[1] * self.components

    @property
    def dimension(self) -> int:
        return self.n_sparse + (0 if self.dense is None else self.dense.shape[1])

    def sparse_matrix(self) -> sp.csr_matrix:
        """``kron(scalar, I_c)`` as a matrix (for checks on small meshes)."""
        if self.components == 1:
            return self.scalar
        return sp.kron(self.scalar, sp.eye(self.components), format="csr")

    def prolong(self, Y: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``P Y`` for reduced coefficients Y (dimension, k): (c n, k) values, written
        into ``out`` if given (C-contiguous).  A new array owns its memory (not a view of
        the (n, c k) product), so the preview's refinement can work in it and shrink it
        in place instead of copying it."""
        c, k = self.components, Y.shape[1]
        Ys = np.ascontiguousarray(Y[: self.n_sparse]).reshape(-1, c * k)
        if out is None:
            out = np.empty((self.scalar.shape[0] * c, k))
        threaded_product(self.scalar, Ys, out=out.reshape(-1, c * k))
        U = out
        if self.dense is not None:
            Yd = Y[self.n_sparse :]
            for rows in row_blocks(U.shape[0]):  # no (c n, k) temporary
                U[rows] += self.dense[rows] @ Yd
        return U

    def restrict(self, X: np.ndarray) -> np.ndarray:
        """``P^T X`` for values X (c n, k): (dimension, k)."""
        c, k = self.components, X.shape[1]
        Xs = np.ascontiguousarray(X).reshape(-1, c * k)
        out = threaded_transpose_product(self.scalar, Xs).reshape(-1, k)
        if self.dense is not None:
            out = np.vstack([out, self.dense.T @ X])
        return out

    def restrict_rows(self, X: np.ndarray, rows: slice) -> np.ndarray:
        """``P[rows]^T X`` for the values X (len(rows), k) of the unknowns ``rows`` (whole
        vertices: with three components, rows start and stop at multiples of 3)."""
        c, k = self.components, X.shape[1]
        block = csr_rows(self.scalar, rows.start // c, rows.stop // c)
        Xs = np.ascontiguousarray(X).reshape(-1, c * k)
        out = np.asarray(block.T @ Xs).reshape(-1, k)
        if self.dense is not None:
            out = np.vstack([out, self.dense[rows].T @ X])
        return out

    def with_dense(self, E: np.ndarray) -> ReducedBasis:
        """The basis with the dense columns E appended."""
        D = E if self.dense is None else np.hstack([self.dense, E])
        return ReducedBasis(self.scalar, self.components, D, self.info)


def reduced_basis(
    mesh: Mesh,
    operator: str,
    samples: int = DEFAULT_SAMPLES,
    radius_factor: float = RADIUS_FACTOR,
    enrich: int = 1,
    seed: int = 0,
    candidates: int | None = None,
) -> ReducedBasis:
    """The reduced space of ``operator`` (see :class:`ReducedBasis`).

    For 3-vector operators (:attr:`.operators.OperatorInfo.vector`, the shells) every
    scalar function times e_x, e_y, e_z, and the three rotations as dense columns; for
    the scalar operators the scalar functions alone.
    ``candidates``: see :func:`farthest_point_samples`.
    """
    centers = farthest_point_samples(mesh.vertices, samples, candidates=candidates, seed=seed)
    P, r = partition_of_unity_basis(mesh, centers, radius_factor, enrich)
    vector = operator_info(operator).vector
    info = {
        "samples": int(len(centers)),
        "support_radius": r,
        "enriched": bool(enrich),
        "polynomial_degree": int(min(max(enrich, 0), 2)),
        "components_per_function": 3 if vector else 1,
    }
    if vector:
        return ReducedBasis(P, 3, rotation_fields(mesh), info)
    return ReducedBasis(P, 1, None, info)


def scalar_functions_per_sample(degree: int) -> int:
    """Scalar basis functions per sample: the partition-of-unity function times 1 (degree
    0), times 1, u, v (degree 1) or times 1, u, v, u^2, uv, v^2 (degree 2)."""
    return {0: 1, 1: 3}.get(int(degree), 6)


def max_samples(n_vertices: int, degree: int) -> int:
    """Most samples a mesh of ``n_vertices`` gets: at least 2 vertices per scalar function
    (and 6 per sample); denser samples make the enriched functions linearly dependent on
    the mesh without adding anything."""
    return n_vertices // (2 * max(scalar_functions_per_sample(degree), 3))
