"""Meshes of several connected components: keep the largest, or compute per component.

A mesh of c components has c constants (Laplacian) or 6 c rigid motions (shells) as
exact zero modes, so k must exceed that before any vibration shows, and the components'
modes are interleaved in one list: computing per component avoids both.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .eigen import ProgressFn
from .mesh import Mesh, MeshReport, _plural, shape_summary
from .operators import DEFAULT_K, OperatorLike, operator_info
from .pipeline import compute_spectrum
from .spectrum import Spectrum
from .validate import check_count


def _by_area(mesh: Mesh) -> tuple[np.ndarray, list[int]]:
    """Each face's component label, and the components largest area first (then most
    vertices, then lowest label)."""
    labels = mesh.component_labels
    face_label = labels[mesh.faces[:, 0]]
    areas = np.bincount(face_label, weights=mesh.face_areas, minlength=mesh.n_components)
    sizes = np.bincount(labels, minlength=mesh.n_components)
    return face_label, sorted(range(mesh.n_components), key=lambda c: (-areas[c], -sizes[c], c))


def split_components(mesh: Mesh) -> list[tuple[Mesh, np.ndarray]]:
    """The connected components, largest area first: (mesh, vertices) per component,
    row i of the component's arrays being vertex ``vertices[i]`` of ``mesh`` (ascending:
    the original vertex order)."""
    solver = mesh.solver_mesh
    if solver is not mesh:  # unused or merged vertices: the parts of the vertices in faces
        return [
            (Mesh(part.vertices, part.faces), solver.file_vertices[vertices])
            for part, vertices in split_components(solver)
        ]
    face_label, order = _by_area(mesh)
    fm = mesh.file_to_mesh  # each part's file_map: its vertex of each file vertex
    out = []
    for c in order:
        vertices = np.flatnonzero(mesh.component_labels == c)
        remap = np.full(mesh.n_vertices, -1, dtype=np.int64)
        remap[vertices] = np.arange(len(vertices))
        faces = remap[mesh.faces[face_label == c]]
        file_map = np.where(fm >= 0, remap[np.maximum(fm, 0)], -1)
        out.append((Mesh(mesh.vertices[vertices], faces, file_map=file_map), vertices))
    return out


def largest_component(mesh: Mesh) -> Mesh:
    """A new mesh of the component with the largest area; its report says what was
    removed.  Vertex numbers stay the input's: the removed components' vertices are
    used by no face (:attr:`~modalviewer.core.mesh.Mesh.unused`)."""
    if not mesh.renumbered:  # the input's numbering: the other components' faces go
        solver = mesh.solver_mesh
        face_label, order = _by_area(solver)
        kept = Mesh(mesh.vertices, mesh.faces[face_label == order[0]], merged_into=mesh.merged_into)
        n_parts = solver.n_components
    else:
        parts = split_components(mesh)
        kept, n_parts = parts[0][0], len(parts)
    # the input's first sentence describes the input: the result's own comes first
    first = shape_summary(mesh)
    messages = [shape_summary(kept)] + [m for m in mesh.report.messages if m != first]
    kept.report = MeshReport(source=mesh.report.source, messages=messages)
    if n_parts == 1:
        kept.report.add("The mesh has one connected component; nothing was removed.")
    else:  # vertex counts are of the vertices faces use
        dropped_v = mesh.solver_mesh.n_vertices - kept.solver_mesh.n_vertices
        dropped_f = mesh.n_faces - kept.n_faces
        share = 100.0 * kept.total_area / mesh.total_area
        kept.report.add(
            f"Kept the largest of {n_parts} connected components "
            f"({_plural(kept.solver_mesh.n_vertices, 'vertex')}, {share:.1f} % of the area); "
            f"removed {_plural(n_parts - 1, 'component')} with "
            f"{_plural(dropped_v, 'vertex')} and {_plural(dropped_f, 'face')}."
        )
    return kept


@dataclass
class ComponentSpectrum:
    """The spectrum (k modes, fewer if it has fewer unknowns) of one connected
    component, on ``mesh``, the component as a mesh of its own whose vertex i is
    ``vertices[i]`` of the original mesh."""

    mesh: Mesh
    vertices: np.ndarray
    spectrum: Spectrum


def compute_spectrum_per_component(
    mesh: Mesh,
    operator: OperatorLike,
    k: int = DEFAULT_K,
    progress: ProgressFn | None = None,
    min_vertices: int = 1,
    **options,
) -> list[ComponentSpectrum]:
    """k modes of each connected component with at least ``min_vertices`` vertices,
    largest area first (a ValueError if there is none), each by
    :func:`~modalviewer.core.pipeline.compute_spectrum` with ``options`` (``bending``,
    ``membrane``, ``cancel``); k is capped at each component's unknowns, and progress
    runs from 0 to 1 over all components, weighted by their vertex counts."""
    operator = operator_info(operator)
    k = check_count(k, "k")
    min_vertices = check_count(min_vertices, "min_vertices", 0)
    parts = [(m, v) for m, v in split_components(mesh) if m.n_vertices >= min_vertices]
    if not parts:
        raise ValueError(f"no component has at least {min_vertices} vertices")
    total = float(sum(m.n_vertices for m, _ in parts))
    done = 0.0
    out = []
    for part, vertices in parts:

        def part_progress(stage: str, fraction: float, base=done, weight=part.n_vertices):
            if progress is not None:
                progress(stage, (base + weight * fraction) / total)

        spec = compute_spectrum(part, operator, k, progress=part_progress, **options)
        out.append(ComponentSpectrum(part, vertices, spec))
        done += part.n_vertices
    return out
