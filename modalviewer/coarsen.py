"""Coarse-to-fine (paper Section 7, Fig. 9): the spectrum of a decimated copy, carried
to the mesh.

The one module of the option: the share of vertices the copy keeps
(:data:`COARSE_FRACTION`), the decimation (:func:`decimated_copy`), the transfer of the
spectrum (:func:`transfer_spectrum`) and both together (:func:`coarse_to_fine_spectrum`).
It lives outside :mod:`modalviewer.core`, which needs numpy and scipy only, because the
decimation is VTK's (through pyvista, imported when a copy is made).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .core.eigen import CancelFn, ProgressFn
from .core.laplacian import lumped_masses
from .core.mesh import Mesh, MeshError, repair_mesh
from .core.operators import operator_info
from .core.pipeline import compute_spectrum
from .core.spectrum import Spectrum

__all__ = [
    "COARSE_FRACTION",
    "decimate_and_locate",
    "decimated_copy",
    "preview_copy",
    "preview_copy_for",
    "preview_copy_refusal",
    "start_preview_copy",
    "transfer_spectrum",
    "coarse_to_fine_spectrum",
]

COARSE_FRACTION = 0.2
"""Share of the vertices the coarse-to-fine copy keeps (:func:`decimated_copy`'s
default; the viewer's cost estimates use it too)."""


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


PREVIEW_COPY_SHARE = 0.03
"""Share of the vertices of the coarse copy a 3D shells preview starts from
(:func:`preview_copy`), between :data:`PREVIEW_COPY_MIN` and :data:`PREVIEW_COPY_MAX`
vertices and at least :data:`PREVIEW_COPY_PER_MODE` per mode."""

PREVIEW_COPY_MIN = 3000
PREVIEW_COPY_MAX = 20000
PREVIEW_COPY_PER_MODE = 30


def preview_copy(mesh: Mesh, k: int, separate_process: bool = True):
    """The coarse copy a 3D shells preview of ``k`` modes starts from
    (:class:`.core.transfer.CoarseCopy`), or None.

    MeshLab's quadric edge collapse (through the optional ``pymeshlab``) to
    :data:`PREVIEW_COPY_SHARE` of the vertices, with its triangle-quality, normal and
    topology safeguards, after a fast first stage (:func:`_first_stage`), and each
    vertex's nearest point on the copy from VTK's cell locator
    (:func:`decimate_and_locate`).  With ``separate_process`` (the default) in a child
    process (:mod:`.processes.copy_main`): MeshLab's and VTK's libraries and
    working memory end with it instead of staying in the process that then computes
    the spectrum.  None without ``pymeshlab``, where the mesh is too small for a copy to
    save work (the copy would keep more than a quarter of its vertices) or where the
    decimation leaves no usable mesh: the preview then starts from its smooth space.
    VTK's own quadric decimation is not used: its copy of the cow subdivided twice had
    triangles of quality 0.03 and a spectrum that missed a mode the estimate does not
    see (4.9 % off, against 0.9 % from MeshLab's)."""
    if _copy_refusal(mesh.n_vertices, k) is not None:
        return None
    target = _copy_target(mesh.n_vertices, k)
    if separate_process:
        made = _decimate_and_locate_in_child(mesh, target)
    else:
        made = decimate_and_locate(mesh.vertices, mesh.faces, target)
    if made is None:
        return None
    from .core.transfer import CoarseCopy

    return CoarseCopy(*made)


def decimate_and_locate(vertices: np.ndarray, faces: np.ndarray, target: int):
    """(copy Mesh, triangles, barycentric) of :func:`preview_copy`: the mesh
    (vertices, faces) decimated to about ``target`` vertices by MeshLab's quadric edge
    collapse, and for each of its vertices the copy's nearest triangle and the
    barycentric coordinates of the nearest point on it (VTK's cell locator); None where
    the decimation leaves no usable mesh."""
    import pymeshlab
    import pyvista as pv

    first = _first_stage(vertices, faces, target)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(np.asarray(first[0], float), np.asarray(first[1], np.int32)))
    del first
    try:
        ms.meshing_decimation_quadric_edge_collapse(
            targetfacenum=int(2 * target),
            qualitythr=0.5,
            preservetopology=True,
            preservenormal=True,
            planarquadric=True,
            optimalplacement=True,
        )
        decimated = ms.current_mesh()
        coarse = repair_mesh(decimated.vertex_matrix(), decimated.face_matrix(), "coarse copy")
    except (pymeshlab.PyMeshLabException, ValueError, MeshError):
        return None
    del ms, decimated
    cell_faces = np.hstack([np.full((coarse.n_faces, 1), 3), coarse.faces]).ravel()
    located = pv.PolyData(np.array(coarse.vertices), cell_faces)
    cells, nearest = located.find_closest_cell(np.array(vertices), return_closest_point=True)
    cells = np.asarray(cells, dtype=np.int64)
    return coarse, cells, _barycentric(nearest, coarse.vertices[coarse.faces[cells]])


FIRST_STAGE_SIZE = 8
"""The fast first stage of :func:`decimate_and_locate` stops at this many times the
copy's vertex count; MeshLab's safeguarded collapse takes it from there."""


def _first_stage(vertices: np.ndarray, faces: np.ndarray, target: int):
    """(vertices, faces): the mesh reduced to about :data:`FIRST_STAGE_SIZE` times
    ``target`` vertices by the optional ``fast-simplification`` (Forstmann's fast
    quadric decimation, borders kept), or as it is where that package is missing or the
    mesh is already that small.  MeshLab's collapse with its quality, normal and
    topology checks costs about 37 us a collapse (the cow Loop x3, 186k vertices to
    5.6k: 6.9 s); the fast stage does most of the collapses at about 3 us each (both
    stages 1.8 s), and MeshLab's safeguards still shape the copy's final triangles.  At 4
    times the size the spot Loop x3's preview was 2.1 % off, at 8 times 1.8 %
    (MeshLab alone: 1.4 %)."""
    if len(vertices) <= 2 * FIRST_STAGE_SIZE * target:
        return vertices, faces
    try:
        import fast_simplification
    except ImportError:
        return vertices, faces
    try:
        return fast_simplification.simplify(
            np.array(vertices, float),  # writeable copies: the binding rejects read-only arrays
            np.array(faces, np.int32),
            target_count=int(2 * FIRST_STAGE_SIZE * target),
            preserve_border=True,
        )
    except (ValueError, RuntimeError):
        return vertices, faces


def _decimate_and_locate_in_child(mesh: Mesh, target: int):
    """:func:`decimate_and_locate` in a child process (:mod:`.processes.copy_main`,
    the arrays through its stdin and stdout); None where it makes no copy."""
    import io
    import subprocess
    import sys

    job = io.BytesIO()
    np.savez(job, vertices=mesh.vertices, faces=mesh.faces, target=int(target))
    run = subprocess.run(
        [sys.executable, "-m", "modalviewer.processes.copy_main"],
        input=job.getvalue(),
        capture_output=True,
    )
    del job
    if run.returncode != 0 or not run.stdout:
        return None
    try:
        with np.load(io.BytesIO(run.stdout), allow_pickle=False) as made:
            coarse = Mesh(made["vertices"], made["faces"])
            return coarse, made["triangles"], made["barycentric"]
    except (OSError, ValueError, KeyError, MeshError):  # not the copy's arrays
        return None


def _copy_target(n_vertices: int, k: int) -> int:
    """Vertices of the coarse copy for ``k`` modes of a mesh of ``n_vertices``."""
    share = int(PREVIEW_COPY_SHARE * n_vertices)
    return min(max(PREVIEW_COPY_MIN, PREVIEW_COPY_PER_MODE * int(k), share), PREVIEW_COPY_MAX)


def _copy_refusal(n_vertices: int, k: int) -> str | None:
    """Why no coarse copy is made for ``k`` modes of a mesh of ``n_vertices`` (in
    words), or None."""
    import importlib.util

    if _copy_target(n_vertices, k) > n_vertices // 4:
        return "the mesh is too small for a coarse copy to save work"
    if importlib.util.find_spec("pymeshlab") is None:
        return "no coarse copy without the optional pymeshlab"
    return None


def preview_copy_refusal(n_vertices: int, operator: str, k: int) -> str | None:
    """Why a preview of ``k`` modes of ``operator`` on a mesh of ``n_vertices`` does not
    start from a coarse copy (in words, for the status line), or None where
    :func:`preview_copy_for` makes one (it may still fail to come out, as
    :func:`preview_copy` says).  Operators whose preview never starts from a copy (all
    but the 3D shells) give ``"no coarse copy for this operator"``."""
    info = operator_info(operator)
    if not info.preview.factor_step:
        return "no coarse copy for this operator"
    if info.factor_out_of_core(n_vertices, k):
        return "the exact solve's factor would not fit in memory"
    return _copy_refusal(n_vertices, k)


def preview_copy_for(mesh: Mesh, operator: str, k: int):
    """:func:`preview_copy` where ``operator``'s preview starts from a coarse copy (the
    3D shells) and the exact solve's factor is predicted to stay in memory
    (:meth:`.core.operators.OperatorInfo.factor_out_of_core`: the start factorises the
    operator in double precision as the exact solve does; out of core its solves would
    cost more than the smooth space's preview, which needs no such factor), else None:
    the one place the viewer's Preview only and ``modalviewer compute --preview``
    decide it."""
    if preview_copy_refusal(mesh.n_vertices, operator, k) is not None:
        return None
    return preview_copy(mesh, k)


def start_preview_copy(mesh: Mesh, operator: str, k: int):
    """:func:`preview_copy_for` on a thread of its own: a ``concurrent.futures.Future``
    of its result (a CoarseCopy or None), with the copy's wall-clock ``seconds`` set
    once it is done.  ``compute_spectrum(..., coarse=future)`` assembles the operator
    and its null space while the copy's process works, and waits for the copy only
    where the preview needs it (the cow Loop x3: assembly and null space about 2.5 s,
    the copy about 4 s).  A daemon thread: a command interrupted meanwhile ends without
    waiting for it (the copy's process ends with this one)."""
    import threading
    import time
    from concurrent.futures import Future

    future = Future()

    def make() -> None:
        started = time.perf_counter()
        try:
            copy = preview_copy_for(mesh, operator, k)
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting computation
            future.seconds = time.perf_counter() - started
            future.set_exception(exc)
            return
        future.seconds = time.perf_counter() - started
        future.set_result(copy)

    threading.Thread(target=make, name="coarse copy", daemon=True).start()
    return future


def _barycentric(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(m, 3) barycentric coordinates of points lying on the triangles ``corners``
    (m, 3, 3), clipped to the triangles (rounding); degenerate triangles give their
    first corner."""
    from .core.transfer import plane_coordinates

    bary, _ = plane_coordinates(points, corners[:, 0], corners[:, 1], corners[:, 2])
    return np.clip(bary, 0.0, 1.0)


def transfer_spectrum(coarse_spec: Spectrum, coarse: Mesh, fine: Mesh) -> Spectrum:
    """Carry a coarse mesh's spectrum to the fine mesh by nearest-vertex lookup.

    Eigenvalues are kept; each fine vertex takes the modes of the nearest coarse vertex.
    The transferred modes are not Mass-orthonormal on the fine mesh; signatures and
    distances computed from them approximate the fine ones (correlation 0.94 for the
    vibration distance on the demo hand decimated to a fifth).
    """
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
    operator: str,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    fraction: float = COARSE_FRACTION,
) -> Spectrum:
    """The ``k`` lowest modes (at most the copy's unknowns) of ``operator`` on a copy of
    ``mesh`` decimated to ``fraction`` of its vertices, carried to ``mesh``."""
    if progress is not None:
        progress("decimating", 0.0)
    coarse = decimated_copy(mesh, fraction)
    k = min(k, operator_info(operator).unknowns(coarse.n_vertices))
    spec = compute_spectrum(coarse, operator, k, bending, membrane, progress, cancel)
    return transfer_spectrum(spec, coarse, mesh)
