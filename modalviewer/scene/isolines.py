"""Isolines of a per-vertex field on a triangle mesh, and which zero crossings are real
nodal lines.  No VTK but pyvista's PolyData."""

from __future__ import annotations

import numpy as np
import pyvista as pv

# The bold zero line is drawn only where the mode is meaningfully non-zero nearby: in a
# triangle whose corner values or whose change over ZERO_LINE_LENGTH (a fraction of the
# bounding-box diagonal, along the gradient) reach ZERO_LINE_FRACTION of max |field|, and
# along lines connected to those where they reach a quarter of it (no dashes).  The
# fraction is low enough to keep the nodal line of a mode whose peak lies far from it and
# high enough that a region where a mode is zero up to round-off draws no line.
ZERO_LINE_FRACTION = 0.003
ZERO_LINE_LENGTH = 0.01


def line_polydata(seg: np.ndarray, disp: np.ndarray | None) -> pv.PolyData:
    """PolyData of (s, 2, 3) segments, with (s, 2, 3) ``disp`` as point data."""
    poly = pv.PolyData()
    n = seg.shape[0]
    if n == 0:
        return poly
    poly.points = seg.reshape(-1, 3)
    cells = np.column_stack([np.full(n, 2), 2 * np.arange(n), 2 * np.arange(n) + 1])
    poly.lines = cells.ravel()
    if disp is not None:
        poly.point_data["displacement"] = disp.reshape(-1, 3)
    return poly


def segments(points, faces, values, levels, displacement=None):
    """Isolines of a piecewise-linear field, one segment per crossed triangle and level
    (vectorised; VTK's contour filter is slower): segments (s, 2, 3), their
    ``displacement`` or None, level (s,), triangle (s,) and the mesh edges (s, 2, 2) their
    ends lie on.  A vertex at a level counts as above it: one segment per crossing."""
    levels = np.sort(np.asarray(levels, dtype=np.float64))
    # levels crossed by each triangle: those in (min, max] of its corner values
    level = np.searchsorted(levels, values, side="right").astype(np.int32)
    l0, l1, l2 = level[faces[:, 0]], level[faces[:, 1]], level[faces[:, 2]]
    lo = np.minimum(np.minimum(l0, l1), l2)  # (m,); faster than min(axis=1)
    hi = np.maximum(np.maximum(l0, l1), l2)
    tri = np.flatnonzero(hi > lo)
    if tri.size == 0:
        empty = np.zeros((0, 2, 3))
        disp = None if displacement is None else empty
        return empty, disp, np.zeros(0), np.zeros(0, np.int64), np.zeros((0, 2, 2), np.int64)
    counts = hi[tri] - lo[tri]
    tri_rep = np.repeat(tri, counts)
    first = np.repeat(lo[tri], counts)
    offsets = np.arange(tri_rep.size) - np.repeat(np.cumsum(counts) - counts, counts)
    c = levels[first + offsets]  # (s,) the level of each segment
    ft = faces[tri_rep]  # (s, 3)
    fv = values[ft]
    a0, a1, a2 = (fv[:, i] >= c for i in range(3))
    # The level separates one corner (the odd one out) from the other two; the segment
    # joins the points where it crosses the two edges at that corner.
    odd = np.where(a0 == a1, 2, np.where(a0 == a2, 1, 0))
    rows = np.arange(tri_rep.size)
    v_odd = ft[rows, odd]
    va = np.column_stack([v_odd, v_odd])  # (s, 2) edge start vertices
    vb = np.column_stack([ft[rows, (odd + 1) % 3], ft[rows, (odd + 2) % 3]])
    fa, fb = values[va], values[vb]
    t = ((c[:, None] - fa) / (fb - fa))[..., None]  # (s, 2, 1)
    seg = points[va] * (1 - t) + points[vb] * t  # (s, 2, 3)
    disp = None
    if displacement is not None:
        disp = displacement[va] * (1 - t) + displacement[vb] * t
    edges = np.stack([np.minimum(va, vb), np.maximum(va, vb)], axis=-1)  # (s, 2, 2)
    return seg, disp, c, tri_rep, edges


def meaningful_zero(
    faces: np.ndarray,
    points: np.ndarray,
    values: np.ndarray,
    triangles: np.ndarray,
    diagonal: float,
    factor: float = 1.0,
) -> np.ndarray:
    """Where a zero crossing in ``triangles`` is a real nodal line (see the constants above;
    ``factor`` scales the fraction).  The gradient term keeps the zero line of low modes
    on fine meshes, whose corner values beside it are tiny."""
    a = float(np.max(np.abs(values)))
    if triangles.size == 0 or a == 0.0:
        return np.zeros(triangles.size, dtype=bool)
    f = faces[triangles]
    fv = values[f]  # (t, 3)
    corner = np.max(np.abs(fv), axis=1)
    x0, x1, x2 = (points[f[:, i]] for i in range(3))
    e1, e2 = x1 - x0, x2 - x0
    d1, d2 = fv[:, 1] - fv[:, 0], fv[:, 2] - fv[:, 0]
    # gradient of the linear interpolant: solve [e1 e2]^T g = (d1, d2) in the plane
    g11 = np.einsum("ij,ij->i", e1, e1)
    g12 = np.einsum("ij,ij->i", e1, e2)
    g22 = np.einsum("ij,ij->i", e2, e2)
    det = g11 * g22 - g12 * g12
    det = np.where(det > 0, det, np.inf)
    c1 = (g22 * d1 - g12 * d2) / det
    c2 = (g11 * d2 - g12 * d1) / det
    grad = np.linalg.norm(c1[:, None] * e1 + c2[:, None] * e2, axis=1)
    local = np.maximum(corner, grad * ZERO_LINE_LENGTH * diagonal)
    return local >= factor * ZERO_LINE_FRACTION * a


def meaningful_zero_lines(faces, points, values, triangles, edges, diagonal) -> np.ndarray:
    """Which zero-line segments to draw, with hysteresis: those passing
    :func:`meaningful_zero`, and those joined to one (through shared mesh ``edges``) by
    segments passing a quarter of it, so a line does not break into dashes."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    strong = meaningful_zero(faces, points, values, triangles, diagonal)
    weak = np.flatnonzero(meaningful_zero(faces, points, values, triangles, diagonal, 0.25))
    if weak.size == 0:
        return strong
    key = edges[weak, :, 0].astype(np.int64) * len(points) + edges[weak, :, 1]
    _, node = np.unique(key.ravel(), return_inverse=True)  # mesh edge -> graph node
    w = weak.size
    rows = np.repeat(np.arange(w), 2)
    n = w + int(node.max()) + 1
    graph = coo_matrix((np.ones(rows.size), (rows, w + node)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    label = label[:w]
    has_strong = np.bincount(label, weights=strong[weak]) > 0
    keep = strong.copy()
    keep[weak] |= has_strong[label]
    return keep
