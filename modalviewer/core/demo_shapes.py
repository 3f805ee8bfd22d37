"""Shapes made in code for demos and benchmarks: the bumpy plate of Fig. 10 and a
second pose of a mesh (numpy only, deterministic)."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh
from .primitives import grid_plate


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
