"""Displacement fields carried from a coarse copy of a surface to the surface itself.

:func:`displacement_prolongation` is the sparse matrix that takes a 3-vector field on
the vertices of a coarse mesh (a decimated copy of the same surface) to one on the
vertices of the fine mesh.  Each fine vertex ``p`` is placed on its nearest coarse
triangle: ``p = sum_i b_i x_i + h n`` (barycentric coordinates b of the nearest point,
signed offset h along the triangle's unit normal n).  Its displacement is

    ``u(p) = sum_i b_i u_i + h dn(u)``

where ``dn(u)`` is the first-order change of the triangle's unit normal under the
corner displacements ``u_i``.  The offset term makes every infinitesimal rigid motion of
a coarse triangle the same rigid motion of the fine vertices over it (``dn = w x n`` for
a rotation w), so a coarse field that bends the coarse mesh without stretching it
stretches the fine mesh only where neighbouring coarse triangles rotate differently:
barycentric interpolation alone would stretch every fine edge that leaves the coarse
triangle's plane, which on a curved surface with thin parts (a tail, an ear) costs far
more membrane energy than the bending it carries.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .mesh import Mesh

__all__ = ["CoarseCopy", "nearest_triangles", "plane_coordinates", "displacement_prolongation"]

CANDIDATES = 12
"""Triangles with the nearest centroids searched for a point's nearest triangle (beside
those around its nearest vertex)."""

_CHUNK = 65536


def _vertex_triangles(mesh: Mesh) -> np.ndarray:
    """(n, d) triangles incident to each vertex, padded with -1 (d the largest valence)."""
    corners = mesh.faces.ravel()
    order = np.argsort(corners, kind="stable")
    counts = np.bincount(corners, minlength=mesh.n_vertices)
    table = np.full((mesh.n_vertices, max(int(counts.max(initial=1)), 1)), -1, dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(corners.size) - np.repeat(starts, counts)
    table[corners[order], slot] = order // 3
    return table


def plane_coordinates(p, a, b, c) -> tuple[np.ndarray, np.ndarray]:
    """(barycentric coordinates (m, 3) of the points p projected into the planes of the
    triangles (a, b, c), all (m, 3); whether each triangle is non-degenerate (m,)).
    Degenerate triangles get (1, 0, 0)."""
    ab, ac, ap = b - a, c - a, p - a
    d00 = np.einsum("ij,ij->i", ab, ab)
    d01 = np.einsum("ij,ij->i", ab, ac)
    d11 = np.einsum("ij,ij->i", ac, ac)
    d20 = np.einsum("ij,ij->i", ap, ab)
    d21 = np.einsum("ij,ij->i", ap, ac)
    den = d00 * d11 - d01 * d01
    ok = den > 1e-30 * np.maximum(d00 * d11, 1e-300)
    den = np.where(ok, den, 1.0)
    v = np.where(ok, (d11 * d20 - d01 * d21) / den, 0.0)
    w = np.where(ok, (d00 * d21 - d01 * d20) / den, 0.0)
    return np.stack([1.0 - v - w, v, w], axis=1), ok


def _closest_on_triangles(p, a, b, c):
    """Nearest points of the triangles (a, b, c) to the points p (all (m, 3)) and their
    barycentric coordinates (m, 3); degenerate triangles give their nearest corner."""
    bary, ok = plane_coordinates(p, a, b, c)
    inside = ok & (bary >= 0.0).all(axis=1)
    best = np.where(inside[:, None], bary, np.nan)
    point = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:] * c
    best_d = np.where(inside, np.einsum("ij,ij->i", p - point, p - point), np.inf)
    # otherwise the nearest point lies on an edge
    corners = (a, b, c)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        x, y = corners[i], corners[j]
        e = y - x
        ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-300)
        t = np.clip(np.einsum("ij,ij->i", p - x, e) / ee, 0.0, 1.0)
        q = x + t[:, None] * e
        d = np.einsum("ij,ij->i", p - q, p - q)
        better = ~inside & (d < best_d)
        if better.any():
            coords = np.zeros((better.sum(), 3))
            coords[:, i] = 1.0 - t[better]
            coords[:, j] = t[better]
            best[better] = coords
            best_d[better] = d[better]
    return best, best_d


def nearest_triangles(coarse: Mesh, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(triangle index (m,), barycentric coordinates (m, 3)) of the nearest point of
    ``coarse`` to each of ``points`` (m, 3), searched among the triangles of the
    :data:`CANDIDATES` nearest triangle centroids and those around the nearest vertex
    (a decimated mesh's long triangles can lie nearest to a point whose nearest vertices
    are none of their corners)."""
    points = np.asarray(points, dtype=np.float64)
    x, faces = coarse.vertices, coarse.faces
    table = _vertex_triangles(coarse)
    q = min(CANDIDATES, coarse.n_faces)
    _, by_centroid = cKDTree(x[faces].mean(axis=1)).query(points, k=q)
    _, by_vertex = cKDTree(x).query(points)
    cand_all = np.hstack([by_centroid.reshape(len(points), q), table[by_vertex]])
    tri_out = np.empty(len(points), dtype=np.int64)
    bary_out = np.empty((len(points), 3))
    for start in range(0, len(points), _CHUNK):
        rows = slice(start, min(start + _CHUNK, len(points)))
        cand = cand_all[rows]
        m, width = cand.shape
        valid = cand >= 0
        flat = np.where(valid, cand, 0).ravel()
        f = faces[flat]
        p = np.repeat(points[rows], width, axis=0)
        bary, dist = _closest_on_triangles(p, x[f[:, 0]], x[f[:, 1]], x[f[:, 2]])
        dist = np.where(valid.ravel(), dist, np.inf).reshape(m, width)
        pick = np.argmin(dist, axis=1)
        index = np.arange(m) * width + pick
        tri_out[rows] = flat[index]
        bary_out[rows] = bary[index]
    return tri_out, bary_out


def _cross_matrices(e: np.ndarray) -> np.ndarray:
    """(m, 3, 3) matrices [e]x with [e]x v = e x v."""
    z = np.zeros(len(e))
    return np.stack(
        [
            np.stack([z, -e[:, 2], e[:, 1]], axis=1),
            np.stack([e[:, 2], z, -e[:, 0]], axis=1),
            np.stack([-e[:, 1], e[:, 0], z], axis=1),
        ],
        axis=1,
    )


@dataclass(frozen=True)
class CoarseCopy:
    """A coarse copy of a mesh (a decimated one) and where each of the mesh's vertices
    lies on it: ``triangles`` (N,) the nearest coarse triangle, ``barycentric`` (N, 3)
    the nearest point's coordinates in it; None: searched by :func:`nearest_triangles`."""

    mesh: Mesh
    triangles: np.ndarray | None = None
    barycentric: np.ndarray | None = None

    def prolongation(self, fine: Mesh) -> sp.csr_matrix:
        """:func:`displacement_prolongation` from this copy to ``fine``."""
        nearest = None if self.triangles is None else (self.triangles, self.barycentric)
        return displacement_prolongation(self.mesh, fine, nearest)


def displacement_prolongation(
    coarse: Mesh, fine: Mesh, nearest: tuple[np.ndarray, np.ndarray] | None = None
) -> sp.csr_matrix:
    """The (3 N, 3 Nc) matrix taking a vertex-major 3-vector field on ``coarse`` to one on
    ``fine`` (see the module's description): 27 entries per fine vertex, those of the
    corners of its nearest coarse triangle.  ``nearest``: (triangles, barycentric) of
    the fine vertices on ``coarse`` where the caller has them (a cell locator's);
    otherwise :func:`nearest_triangles`."""
    tri, bary = nearest_triangles(coarse, fine.vertices) if nearest is None else nearest
    corners = coarse.faces[tri]  # (N, 3)
    x = coarse.vertices
    x0, x1, x2 = x[corners[:, 0]], x[corners[:, 1]], x[corners[:, 2]]
    e1, e2 = x1 - x0, x2 - x0
    cross = np.cross(e1, e2)
    double_area = np.maximum(np.linalg.norm(cross, axis=1), 1e-300)
    n = cross / double_area[:, None]
    nearest = bary[:, :1] * x0 + bary[:, 1:2] * x1 + bary[:, 2:] * x2
    h = np.einsum("ij,ij->i", fine.vertices - nearest, n)
    # dn = (I - n n^T)(de1 x e2 + e1 x de2) / |e1 x e2|, de1 = u1 - u0, de2 = u2 - u0
    tangential = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
    scale = (h / double_area)[:, None, None]
    c1 = -scale * (tangential @ _cross_matrices(e2))
    c2 = scale * (tangential @ _cross_matrices(e1))
    blocks = bary[:, :, None, None] * np.eye(3)[None, None]
    blocks[:, 0] -= c1 + c2
    blocks[:, 1] += c1
    blocks[:, 2] += c2
    N = fine.n_vertices
    # row 3 v + r holds, for each corner i and component c, the entry of column
    # 3 corner_i + c: the blocks in (vertex, r, corner, c) order fill the rows in turn
    data = np.ascontiguousarray(blocks.transpose(0, 2, 1, 3)).ravel()
    columns = np.broadcast_to(3 * corners[:, None, :, None] + np.arange(3), (N, 3, 3, 3))
    indptr = np.arange(0, 27 * N + 1, 9, dtype=np.int64)
    return sp.csr_matrix(
        (data, np.ascontiguousarray(columns).ravel(), indptr), shape=(3 * N, 3 * coarse.n_vertices)
    )
