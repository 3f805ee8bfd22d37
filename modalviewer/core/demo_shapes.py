"""The demo meshes of ``assets/`` (paper Figs. 1, 3, 6, 8, 10), made in code.

numpy only, deterministic.  ``scripts/make_assets.py`` writes them to ``assets/``;
the hand needs an iso-surface extraction and is built there with VTK.
"""

from __future__ import annotations

import numpy as np

from .cleaning import repair_mesh
from .mesh import Mesh
from .primitives import grid_plate

PLATE_N = (48, 24)  # grid cells of the Fig. 1 plate, 2 x 1
FOLD_X = 1.0  # the fold runs along the grid line x = 1


def plate() -> Mesh:
    """Flat 2 x 1 plate, 49 x 25 vertices."""
    return grid_plate(PLATE_N[0], PLATE_N[1], width=2.0, height=1.0)


def folded_plate(angle_degrees: float = 90.0) -> Mesh:
    """:func:`plate` folded isometrically along the mesh line x = 1 (edge lengths kept)."""
    base = plate()
    v = np.array(base.vertices)
    right = v[:, 0] > FOLD_X + 1e-12
    a = np.radians(angle_degrees)
    d = v[right, 0] - FOLD_X
    v[right, 0] = FOLD_X + d * np.cos(a)
    v[right, 2] = d * np.sin(a)
    return Mesh(v, base.faces)


def bent_pose(mesh: Mesh, angle_degrees: float = 40.0, at: float = 0.5, width: float = 0.4) -> Mesh:
    """A second pose of ``mesh``, vertex for vertex (a correspondence's ground truth is the
    identity): the part beyond ``at`` of the bounding box's longest extent turned by
    ``angle_degrees`` about an axis along its middle extent, the turn growing smoothly over
    ``width`` of that extent, so a flat shape bends as a sheet does (nearly isometrically)."""
    v = np.array(mesh.vertices)
    lo, hi = v.min(axis=0), v.max(axis=0)
    extent = hi - lo
    along, third = int(np.argmax(extent)), int(np.argmin(extent))
    s = (v[:, along] - lo[along]) / extent[along]
    x = np.clip((s - at) / width + 0.5, 0.0, 1.0)
    phi = np.radians(angle_degrees) * x * x * (3.0 - 2.0 * x)
    pivot = 0.5 * (lo + hi)
    pivot[along] = lo[along] + at * extent[along]
    a, b = v[:, along] - pivot[along], v[:, third] - pivot[third]
    out = v.copy()
    out[:, along] = pivot[along] + np.cos(phi) * a - np.sin(phi) * b
    out[:, third] = pivot[third] + np.sin(phi) * a + np.cos(phi) * b
    return Mesh(out, mesh.faces)


def bumpy_plate(n: int = 80, seed: int = 3) -> Mesh:
    """Unit-square plate with a dozen smooth bumps and dents of varied size (Fig. 10)."""
    base = grid_plate(n, n)
    v = np.array(base.vertices)
    rng = np.random.default_rng(seed)
    for _ in range(12):
        cx, cy = rng.uniform(0.15, 0.85, 2)
        r = rng.uniform(0.04, 0.12)
        h = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0) * r
        v[:, 2] += h * np.exp(-((v[:, 0] - cx) ** 2 + (v[:, 1] - cy) ** 2) / (2 * r * r))
    return Mesh(v, base.faces)


def voxel_surface(solid: np.ndarray, size: float = 1.0) -> Mesh:
    """Outward-oriented boundary of a union of cubes ``solid[i, j, k]`` (edge ``size``),
    two triangles per square, coinciding corners merged.  The solid must not touch
    itself along an edge only (non-manifold)."""
    solid = np.pad(np.asarray(solid, dtype=bool), 1)
    quads = []
    # for each axis and direction, faces where solid meets empty
    corners = {
        0: np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]),
        1: np.array([[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]),
        2: np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    }
    for axis in range(3):
        for direction in (1, -1):
            neighbour = np.roll(solid, -direction, axis=axis)
            cells = np.argwhere(solid & ~neighbour)
            quad = corners[axis] + (direction == 1) * np.eye(3, dtype=int)[axis]
            if direction == -1:
                quad = quad[::-1]  # reversed winding: normal along -axis
            quads.append(cells[:, None, :] + quad[None, :, :])
    q = np.concatenate(quads).reshape(-1, 3).astype(np.float64) - 1.0  # undo the padding
    idx = np.arange(len(q)).reshape(-1, 4)
    faces = np.concatenate([idx[:, [0, 1, 2]], idx[:, [0, 2, 3]]])
    mesh = repair_mesh(q * size, faces, source="voxels")
    return Mesh(mesh.vertices, mesh.faces)


def double_torus(cells: int = 4) -> Mesh:
    """A 7 x 4 x 1 slab with two square holes, ``cells`` voxels per unit length: genus two,
    flat faces bounded by sharp edges (Fig. 3)."""
    c = cells
    solid = np.ones((7 * c, 4 * c, 1 * c), dtype=bool)
    solid[1 * c : 3 * c, 1 * c : 3 * c, :] = False
    solid[4 * c : 6 * c, 1 * c : 3 * c, :] = False
    return voxel_surface(solid, 1.0 / c)


def machined_part(cells: int = 4) -> Mesh:
    """An L-shaped bracket with a through hole and a raised boss (rocker-arm spirit, Fig. 8)."""
    c = cells
    solid = np.zeros((10 * c, 4 * c, 6 * c), dtype=bool)
    solid[:, :, : 1 * c] = True  # base plate 10 x 4 x 1
    solid[: 1 * c, :, :] = True  # upright wall 1 x 4 x 6
    solid[6 * c : 8 * c, 1 * c : 3 * c, : 1 * c] = False  # through hole in the base
    solid[2 * c : 4 * c, 1 * c : 3 * c, 1 * c : 2 * c] = True  # boss on the base
    return voxel_surface(solid, 1.0 / c)
