"""Coarse-to-fine (paper Section 7, Fig. 9): the spectrum of a decimated copy, carried
to the mesh.  Outside :mod:`modalviewer.core` (numpy and scipy only) because the
decimation is VTK's, through pyvista, imported when a copy is made."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .core.cleaning import repair_mesh
from .core.eigen import CancelFn, ProgressFn
from .core.laplacian import lumped_masses
from .core.mesh import Mesh
from .core.operators import OperatorLike, operator_info
from .core.pipeline import compute_spectrum
from .core.spectrum import Spectrum

COARSE_FRACTION = 0.2
"""Share of the vertices the coarse-to-fine copy keeps (:func:`decimated_copy`'s
default; the viewer's cost estimates use it too)."""


def decimated_copy(mesh: Mesh, fraction: float = COARSE_FRACTION) -> Mesh:
    """The mesh decimated to about ``fraction`` of its vertices, repaired and reported, by
    VTK's progressive decimation with topology preserved (quadric decimation leaves
    slivers on flat regions, which make the shells Hessian numerically indefinite)."""
    import pyvista as pv

    poly = pv.PolyData.from_regular_faces(np.array(mesh.vertices), mesh.faces).decimate_pro(
        1.0 - fraction, preserve_topology=True
    )
    arrays = np.asarray(poly.points), np.asarray(poly.faces).reshape(-1, 4)[:, 1:]
    return repair_mesh(*arrays, source="coarse copy")


def transfer_spectrum(coarse_spec: Spectrum, coarse: Mesh, fine: Mesh) -> Spectrum:
    """The coarse spectrum on the fine mesh, each vertex taking its nearest coarse vertex's
    modes (not Mass-orthonormal there: signatures and distances approximate the fine ones)."""
    _, nearest = cKDTree(coarse.vertices).query(fine.vertices)
    params = dict(coarse_spec.parameters)
    params.update(transferred_from=coarse.hash, coarse_vertices=coarse.n_vertices)
    return Spectrum(
        eigenvalues=coarse_spec.eigenvalues.copy(),
        modes=coarse_spec.modes[nearest].copy(),
        operator=coarse_spec.operator,
        mass=lumped_masses(fine),
        residuals=coarse_spec.residuals.copy(),
        mesh_hash=fine.hash,
        parameters=params,
    )


def coarse_to_fine_spectrum(
    mesh: Mesh,
    operator: OperatorLike,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    fraction: float = COARSE_FRACTION,
) -> Spectrum:
    """The ``k`` lowest modes of ``operator`` on a decimated copy, carried to ``mesh``."""
    if progress is not None:
        progress("decimating", 0.0)
    coarse = decimated_copy(mesh, fraction)
    operator = operator_info(operator)
    k = min(k, operator.unknowns(coarse.n_vertices))
    spec = compute_spectrum(coarse, operator, k, bending, membrane, progress, cancel)
    return transfer_spectrum(spec, coarse, mesh)
