"""Meshes of several connected components: keep the largest, or compute per component.

A spectrum of a mesh with c components starts with c constants (Laplacian) or 6 c rigid
motions (Discrete Shells): :func:`~modalviewer.core.pipeline.compute_spectrum` returns
them as exact zero modes and says how many (``spec.null_space_dimension``,
``spec.parameters["null_space"]``), but k must then exceed that number before any
vibration shows up, and the non-zero modes of all components are interleaved in one
list.  Two ways out, both plain functions of the mesh:

* :func:`largest_component` returns a new :class:`Mesh` of the component with the
  largest area (scanner debris and loose parts dropped), with a report of what was
  removed, like every repair.
* :func:`compute_spectrum_per_component` computes k modes of each component on its own
  and returns one :class:`ComponentSpectrum` per component, largest first.

:func:`split_components` gives the components themselves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .eigen import CancelFn, ProgressFn
from .mesh import Mesh, MeshReport, shape_summary
from .pipeline import compute_spectrum
from .spectrum import Spectrum
from .validate import check_count

__all__ = [
    "ComponentSpectrum",
    "compute_spectrum_per_component",
    "largest_component",
    "split_components",
]


def _plural(count: int, word: str) -> str:
    if count == 1:
        return f"{count} {word}"
    return f"{count} {word[:-6] + 'vertices' if word.endswith('vertex') else word + 's'}"


def split_components(mesh: Mesh) -> list[tuple[Mesh, np.ndarray]]:
    """The connected components, largest area first.

    Each component keeps the map to the file's vertex numbers
    (:attr:`~modalviewer.core.mesh.Mesh.file_to_mesh`): the file's vertices of other
    components map to -1 in it.

    Parameters
    ----------
    mesh : Mesh
        The surface, n vertices.

    Returns
    -------
    list of (Mesh, ndarray of int, shape (n_c,))
        Per component its mesh and its vertex indices in ``mesh``: row i of the
        component's arrays belongs to vertex ``vertices[i]`` of ``mesh`` (ascending, so
        the component keeps the original vertex order).
    """
    labels = mesh.component_labels
    face_label = labels[mesh.faces[:, 0]]
    areas = np.bincount(face_label, weights=mesh.face_areas, minlength=mesh.n_components)
    sizes = np.bincount(labels, minlength=mesh.n_components)
    order = sorted(range(mesh.n_components), key=lambda c: (-areas[c], -sizes[c], c))
    out = []
    for c in order:
        vertices = np.flatnonzero(labels == c)
        remap = np.full(mesh.n_vertices, -1, dtype=np.int64)
        remap[vertices] = np.arange(len(vertices))
        faces = remap[mesh.faces[face_label == c]]
        out.append(
            (Mesh(mesh.vertices[vertices], faces, file_map=mesh.file_map_after(remap)), vertices)
        )
    return out


def largest_component(mesh: Mesh) -> Mesh:
    """A new mesh of the component with the largest area.

    Vertex numbers stay the file's (the removed components' vertices are, for the
    result, used by no face).

    Parameters
    ----------
    mesh : Mesh
        The surface.

    Returns
    -------
    Mesh
        The largest component; ``result.report`` says what was removed (the input's report
        messages come first).  A mesh with one component is returned as a copy, with the
        report saying so.
    """
    parts = split_components(mesh)
    kept, vertices = parts[0]
    # the input's first sentence describes the input: the result's own comes first
    before = shape_summary(mesh)
    messages = [shape_summary(kept)] + [m for m in mesh.report.messages if m != before]
    report = MeshReport(source=mesh.report.source, messages=messages)
    if len(parts) == 1:
        report.add("The mesh has one connected component; nothing was removed.")
    else:
        dropped_v = mesh.n_vertices - kept.n_vertices
        dropped_f = mesh.n_faces - kept.n_faces
        share = 100.0 * kept.total_area / mesh.total_area
        report.add(
            f"Kept the largest of {mesh.n_components} connected components "
            f"({_plural(kept.n_vertices, 'vertex')}, {share:.1f} % of the area); removed "
            f"{_plural(len(parts) - 1, 'component')} with {_plural(dropped_v, 'vertex')} "
            f"and {_plural(dropped_f, 'face')}."
        )
    return Mesh(kept.vertices, kept.faces, report=report, file_map=kept.file_map)


@dataclass
class ComponentSpectrum:
    """The spectrum of one connected component.

    Attributes
    ----------
    mesh : the component as a mesh of its own.
    vertices : (n_c,) its vertex indices in the original mesh.
    spectrum : k modes of the component (fewer if it has fewer unknowns), on ``mesh``.
    """

    mesh: Mesh
    vertices: np.ndarray
    spectrum: Spectrum

    def mode_on_original(self, j: int, n_vertices: int) -> np.ndarray:
        """Mode j as a field on the original mesh: (n,) or (n, 3), zero elsewhere (an
        eigenvector of the whole mesh's operator too, which is block diagonal)."""
        mode = self.spectrum.mode(j)
        out = np.zeros((n_vertices, *mode.shape[1:]))
        out[self.vertices] = mode
        return out


def compute_spectrum_per_component(
    mesh: Mesh,
    operator: str,
    k: int = 100,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    min_vertices: int = 1,
) -> list[ComponentSpectrum]:
    """k modes of each connected component with at least ``min_vertices`` vertices,
    largest area first.

    Parameters
    ----------
    mesh : Mesh
        The surface.
    operator, bending, membrane, progress, cancel
        As for :func:`~modalviewer.core.pipeline.compute_spectrum`; progress runs from 0 to
        1 over all components, weighted by their vertex counts.
    k : int
        Modes per component, capped at each component's unknowns.
    min_vertices : int
        Smaller components are left out.

    Returns
    -------
    list of ComponentSpectrum
        One per component computed, largest area first.

    Raises
    ------
    ValueError
        If no component has at least ``min_vertices`` vertices.
    """
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

        spec = compute_spectrum(
            part, operator, k, bending, membrane, progress=part_progress, cancel=cancel
        )
        out.append(ComponentSpectrum(part, vertices, spec))
        done += part.n_vertices
    return out
