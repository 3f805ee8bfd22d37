"""Simple meshes made in code: plates, icospheres, tori (for tests, demos and benchmarks)."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh


def grid_plate(nx: int = 10, ny: int = 10, width: float = 1.0, height: float = 1.0) -> Mesh:
    """Flat rectangle [0, width] x [0, height] in z = 0 with (nx+1)(ny+1) vertices, each
    cell split along alternating diagonals (a symmetric "criss" pattern)."""
    xs, ys = np.linspace(0, width, nx + 1), np.linspace(0, height, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    v = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    flip = ((i + j) % 2 == 1).ravel()
    f1 = np.where(flip[:, None], np.column_stack([a, b, d]), np.column_stack([a, b, c]))
    f2 = np.where(flip[:, None], np.column_stack([b, c, d]), np.column_stack([a, c, d]))
    return Mesh(v, np.vstack([f1, f2]))


def icosphere(subdivisions: int = 3, radius: float = 1.0) -> Mesh:
    """Sphere of ``radius`` from a subdivided icosahedron (10 * 4^s + 2 vertices)."""
    t = (1.0 + 5**0.5) / 2.0
    v = np.array(
        [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]],
        dtype=np.float64,
    )  # fmt: skip
    f = np.array(
        [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]],
        dtype=np.int64,
    )  # fmt: skip
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    for _ in range(subdivisions):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        mid = v[uniq[:, 0]] + v[uniq[:, 1]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = len(f)
        e01, e12, e20 = inv[:m] + len(v), inv[m : 2 * m] + len(v), inv[2 * m :] + len(v)
        v = np.vstack([v, mid])
        f = np.vstack(
            [
                np.column_stack([f[:, 0], e01, e20]),
                np.column_stack([f[:, 1], e12, e01]),
                np.column_stack([f[:, 2], e20, e12]),
                np.column_stack([e01, e12, e20]),
            ]
        )
    return Mesh(v * radius, f)


def torus(n_major: int = 32, n_minor: int = 16, major: float = 1.0, minor: float = 0.3) -> Mesh:
    """Torus around the z axis with ``n_major * n_minor`` vertices."""
    u = np.linspace(0, 2 * np.pi, n_major, endpoint=False)
    w = np.linspace(0, 2 * np.pi, n_minor, endpoint=False)
    U, W = np.meshgrid(u, w, indexing="ij")
    r = major + minor * np.cos(W)
    v = np.column_stack(
        [(r * np.cos(U)).ravel(), (r * np.sin(U)).ravel(), (minor * np.sin(W)).ravel()]
    )
    idx = np.arange(n_major * n_minor).reshape(n_major, n_minor)
    a = idx
    b = np.roll(idx, -1, axis=0)
    c = np.roll(np.roll(idx, -1, axis=0), -1, axis=1)
    d = np.roll(idx, -1, axis=1)
    f = np.vstack(
        [np.column_stack([a.ravel(), b.ravel(), c.ravel()]),
         np.column_stack([a.ravel(), c.ravel(), d.ravel()])]
    )  # fmt: skip
    return Mesh(v, f)
