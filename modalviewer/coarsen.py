"""A decimated copy of a mesh for the coarse-to-fine option (VTK; outside the core)."""

from __future__ import annotations

import numpy as np

from .core.mesh import Mesh, repair_mesh

__all__ = ["COARSE_FRACTION", "decimated_copy"]

COARSE_FRACTION = 0.2
"""Default share of the vertices kept by :func:`decimated_copy`."""


def decimated_copy(mesh: Mesh, fraction: float = COARSE_FRACTION) -> Mesh:
    """The mesh decimated to about ``fraction`` of its vertices, repaired and reported.

    VTK's progressive decimation with topology preserved: quadric decimation left slivers
    (triangle quality 7e-7) on flat regions of subdivided meshes, which make the shells
    Hessian numerically indefinite.
    """
    import pyvista as pv

    faces = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
    poly = pv.PolyData(np.array(mesh.vertices), faces).decimate_pro(
        1.0 - fraction, preserve_topology=True
    )
    arrays = np.asarray(poly.points), np.asarray(poly.faces).reshape(-1, 4)[:, 1:]
    return repair_mesh(*arrays, source="coarse copy")
