"""Sliver repair: needle and cap triangles removed by edge flips and collapses (PyMeshLab).

Nearly degenerate triangles, *needles* (one edge much shorter than the others) and
*caps* (one vertex almost on the opposite edge), make the Discrete Shells Hessian
numerically indefinite, so its factorisation fails.  :func:`fix_slivers` removes them
with MeshLab's filters and never simply deletes a face, so a closed surface stays
closed.  ``pymeshlab`` is imported only when it runs.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..core.mesh import Mesh, MeshError, MeshReport, _plural

SLIVER_QUALITY = 1e-3
"""Quality below which a triangle is counted as a sliver in reports."""


@dataclass
class SliverReport(MeshReport):
    """What :func:`fix_slivers` changed, as numbers and as sentences (``str(report)``).
    Quality is :func:`~modalviewer.core.mesh.triangle_quality`'s; distances are relative
    to the input's bounding-box diagonal."""

    min_quality: float = 0.05
    triangles_before: int = 0
    triangles_after: int = 0
    triangles_changed: int = 0  # input triangles not in the output unchanged
    vertices_removed: int = 0
    below_min_quality_before: int = 0
    below_min_quality_after: int = 0
    slivers_before: int = 0  # quality below SLIVER_QUALITY
    slivers_after: int = 0
    worst_quality_before: float = math.nan
    worst_quality_after: float = math.nan
    max_vertex_shift: float = 0.0  # largest move of a kept vertex (remeshed: off the input)
    max_deviation: float = 0.0  # Hausdorff distance between the surfaces, at the vertices
    method: str = ""
    seconds: float = 0.0


def _topology(mesh: Mesh) -> dict:
    return {
        "boundary edges": mesh.n_boundary_edges,
        "non-manifold edges": mesh.n_nonmanifold_edges,
        "components": mesh.n_components,
        "Euler characteristic": mesh.n_vertices - len(mesh.edges) + mesh.n_faces,
        "consistent orientation": mesh.is_consistently_oriented,
    }


_METHODS = {
    "flip+collapse": "edge flips and collapses (MeshLab's T-vertex removal)",
    "collapse": "edge collapses (MeshLab's T-vertex removal)",
    "remesh": (
        "isotropic remeshing of the slivers and their neighbours only (MeshLab: edge "
        "splits, collapses and flips, tangential smoothing projected back on the surface)"
    ),
}


def _run_meshlab(vertices, faces, quality, method: str, min_quality: float):
    """Apply ``method`` with ``pymeshlab``; (vertices, faces, tags, ms) where tags[i] is
    the input index of output vertex i (not a whole number for a vertex made by a split,
    and then possibly a wrong one: check the position too)."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    tags = np.arange(len(vertices), dtype=np.float64)  # exact in float64
    ms.add_mesh(
        pymeshlab.Mesh(
            vertices, faces.astype(np.int32), v_scalar_array=tags, f_scalar_array=quality
        )
    )
    ratio = math.sqrt(3.0) / min_quality
    if method == "flip+collapse":
        try:
            ms.meshing_remove_t_vertices(method="Edge Flip", threshold=ratio, repeat=True)
        except pymeshlab.PyMeshLabException:
            pass  # flips need a vertex-manifold surface; collapses do not
    if method in ("flip+collapse", "collapse"):
        ms.meshing_remove_t_vertices(method="Edge Collapse", threshold=ratio, repeat=True)
    if method == "remesh":
        bad = quality < min_quality
        near = np.zeros(len(vertices), dtype=bool)
        near[faces[bad].ravel()] = True
        region = faces[near[faces].any(axis=1)]
        edges = vertices[region] - vertices[np.roll(region, -1, axis=1)]  # (r, 3, 3)
        target = float(np.median(np.linalg.norm(edges, axis=-1)))
        ms.compute_selection_by_condition_per_face(condselect=f"fq < {min_quality!r}")
        ms.apply_selection_dilatation()
        ms.meshing_isotropic_explicit_remeshing(
            iterations=2,
            selectedonly=True,
            targetlen=pymeshlab.PureValue(target),
            featuredeg=60.0,
            checksurfdist=False,
            reprojectflag=True,
        )
    ms.meshing_remove_unreferenced_vertices()
    out = ms.current_mesh()
    v = np.array(out.vertex_matrix(), dtype=np.float64)
    f = np.array(out.face_matrix(), dtype=np.int64)
    return v, f, np.array(out.vertex_scalar_array(), dtype=np.float64), ms


def _hausdorff(ms, sampled_id: int, target_id: int, n_samples: int) -> float:
    """Largest distance from a vertex of mesh ``sampled_id`` to the surface ``target_id``."""
    import pymeshlab

    res = ms.get_hausdorff_distance(  # sampling the vertices only: the default
        sampledmesh=sampled_id,
        targetmesh=target_id,
        samplenum=n_samples,
        maxdist=pymeshlab.PercentageValue(100.0),
    )
    return float(res["max"])


def fix_slivers(mesh: Mesh, min_quality: float = 0.05, progress=None) -> Mesh:
    """A copy of ``mesh`` without needle and cap triangles; ``result.report`` is a
    :class:`SliverReport`, its distances relative to the bounding-box diagonal.

    Three repairs are tried in turn and the first is returned whose result keeps the
    input's topology (boundary and non-manifold edges, components, Euler characteristic,
    orientation), has no degenerate face and fewer triangles below ``min_quality``:
    MeshLab's T-vertex removal by flips then collapses; by collapses alone; isotropic
    remeshing of the slivers and the faces around them.  MeshLab's collapses do not
    check the link condition (one bad collapse can make an edge non-manifold); the
    remeshing does, more slowly.  MeshLab's criterion ``L / height >= sqrt(3) /
    min_quality`` (L the longest edge) leaves triangles of quality above about
    ``min_quality`` and treats those below ``1.33 * min_quality``.  Where nothing was
    changed the result has the input's vertices and numbering, else MeshLab's (the
    report says so).  ``progress(stage, fraction)`` is called before each repair tried
    and before the measurements.  MeshError if ``pymeshlab`` is not installed or no
    repair keeps the topology.
    """
    if not 0.0 < min_quality < 1.0:
        raise ValueError(f"min_quality must be between 0 and 1, got {min_quality}")
    progress = progress or (lambda stage, fraction: None)
    started = time.perf_counter()
    v0, f0 = mesh.vertices, mesh.faces
    q0 = mesh.face_quality
    diag = mesh.bounding_box_diagonal
    report = SliverReport(
        source=mesh.report.source,
        min_quality=min_quality,
        triangles_before=mesh.n_faces,
        below_min_quality_before=int((q0 < min_quality).sum()),
        slivers_before=int((q0 < SLIVER_QUALITY).sum()),
        worst_quality_before=float(q0.min()),
    )
    if report.below_min_quality_before == 0:  # the mesh as it is
        report.triangles_after = mesh.n_faces
        report.worst_quality_after = report.worst_quality_before
        report.seconds = time.perf_counter() - started
        report.add(
            f"No triangle has quality below {min_quality:g} (worst "
            f"{report.worst_quality_before:.3g}); nothing was changed."
        )
        return Mesh(
            mesh.vertices, mesh.faces, report=report, file_map=mesh.file_map,
            merged_into=mesh.merged_into,
        )  # fmt: skip
    try:
        import pymeshlab
    except ImportError:
        raise MeshError(
            "fix_slivers needs the optional pymeshlab package (GPL-3.0): "
            "pip install 'modalviewer[repair]' (or pip install pymeshlab)"
        ) from None
    result, method, tags, ms = _first_repair(mesh, report, min_quality, progress)
    q1 = result.face_quality
    whole = (tags == np.rint(tags)) & (tags >= 0) & (tags < mesh.n_vertices)
    origin = np.where(whole, np.rint(tags), 0).astype(np.int64)
    moved = np.linalg.norm(result.vertices - v0[origin], axis=1)
    unchanged = _unchanged_triangles(mesh, result, origin, whole & (moved == 0))
    progress("measuring the change", 0.9)
    out_id = ms.current_mesh_id()
    ms.add_mesh(pymeshlab.Mesh(v0, f0.astype(np.int32)))
    in_id = ms.current_mesh_id()
    to_new = _hausdorff(ms, in_id, out_id, mesh.n_vertices)
    to_old = _hausdorff(ms, out_id, in_id, result.n_vertices)

    report.triangles_after = result.n_faces
    report.triangles_changed = int((~unchanged).sum())
    report.vertices_removed = mesh.n_vertices - result.n_vertices
    report.below_min_quality_after = int((q1 < min_quality).sum())
    report.slivers_after = int((q1 < SLIVER_QUALITY).sum())
    report.worst_quality_after = float(q1.min())
    if method == "remesh":  # vertices are new or smoothed: how far they are off the input
        report.max_vertex_shift = to_old / diag
    else:
        report.max_vertex_shift = float(moved[whole].max(initial=0.0)) / diag
    report.max_deviation = max(to_new, to_old) / diag
    report.seconds = time.perf_counter() - started
    progress("done", 1.0)
    report.add(
        "The repair numbers the vertices anew: vertex numbers (picks, --vertex, CSV rows, "
        "sessions) are now the repaired mesh's, not the file's."
    )
    report.messages.insert(0, _summary(report, method == "remesh"))
    return result


def _first_repair(mesh: Mesh, report: SliverReport, min_quality: float, progress):
    """(repaired mesh, method, vertex tags, MeshSet) of the first of :data:`_METHODS`
    whose result keeps the topology and has fewer triangles below ``min_quality``; a
    MeshError naming why each was refused if none does.  Sets ``report.method`` and
    notes the refused ones in it."""
    import pymeshlab

    before = _topology(mesh)
    refused = []
    for number, method in enumerate(_METHODS):
        progress(f"fixing slivers: {_METHODS[method].split(' (')[0]}", 0.8 * number / 3)
        try:
            v, f, tags, ms = _run_meshlab(
                mesh.vertices, mesh.faces, mesh.face_quality, method, min_quality
            )
            candidate = Mesh(v, f, report=report)
        except (pymeshlab.PyMeshLabException, MeshError) as exc:  # MeshError: a degenerate face
            refused.append(f"{method}: {exc}")
            continue
        after = _topology(candidate)
        if after != before:
            changes = [f"{n} {before[n]} -> {after[n]}" for n in before if before[n] != after[n]]
            refused.append(f"{method}: {', '.join(changes)}")
            continue
        if (candidate.face_quality < min_quality).sum() >= report.below_min_quality_before:
            refused.append(f"{method}: no better")
            continue
        report.method = _METHODS[method]
        if refused:
            report.add(
                "Simpler repairs were refused because they would have changed the surface: "
                + "; ".join(refused)
                + "."
            )
        return candidate, method, tags, ms
    raise MeshError(
        "the slivers could not be removed without changing the surface's topology ("
        + "; ".join(refused)
        + "); remesh it in a mesh tool"
    )


def _unchanged_triangles(mesh: Mesh, result: Mesh, origin, same) -> np.ndarray:
    """(m,) bool: the input triangles the output has with the same, unmoved vertices
    (``same``; ``origin``: each output vertex's input index)."""
    still = result.faces[same[result.faces].all(axis=1)]
    key_out = np.sort(origin[still], axis=1)
    key_in = np.sort(mesh.faces, axis=1)
    base = max(mesh.n_vertices, 1)
    code_out = (key_out[:, 0] * base + key_out[:, 1]) * base + key_out[:, 2]
    code_in = (key_in[:, 0] * base + key_in[:, 1]) * base + key_in[:, 2]
    return np.isin(code_in, code_out)


def _summary(report: SliverReport, remeshed: bool) -> str:
    """The report's first sentence: what changed, by how much, and how far it moved."""
    return (
        f"Changed {report.triangles_changed} of {_plural(report.triangles_before, 'triangle')}"
        f" by {report.method} ({_plural(report.triangles_after, 'triangle')} now, "
        f"{_plural(report.vertices_removed, 'vertex')} fewer): triangles below quality "
        f"{report.min_quality:g} {report.below_min_quality_before} -> "
        f"{report.below_min_quality_after}, below {SLIVER_QUALITY:g} "
        f"{report.slivers_before} -> {report.slivers_after}, worst quality "
        f"{report.worst_quality_before:.2g} -> {report.worst_quality_after:.2g}; "
        + (
            f"new and smoothed vertices lie within {report.max_vertex_shift:.1e} of the "
            "input surface"
            if remeshed
            else f"vertices moved at most {report.max_vertex_shift:.1e}"
        )
        + " and the two surfaces are within "
        f"{report.max_deviation:.1e} of each other (of the bounding-box diagonal); "
        f"boundary, components and Euler characteristic unchanged; {report.seconds:.2f} s."
    )
