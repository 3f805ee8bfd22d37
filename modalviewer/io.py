"""Reading meshes from files, with repair and a report.  OBJ, PLY, STL and OFF go
through the strict :mod:`modalviewer.readers`; VTK and VTP through pyvista, imported only
then (``import modalviewer`` stays free of VTK); every other extension meshio reads
through meshio where it is installed (the ``meshio`` extra)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .core.cleaning import repair_mesh
from .core.mesh import Mesh, MeshError, MeshReport, _plural, shape_summary
from .extras import MissingExtraError, extra_needed
from .readers import read_mesh_file

SUPPORTED_EXTENSIONS = (".obj", ".ply", ".stl", ".off", ".vtk", ".vtp")


def pyvista_arrays(data) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(vertices, triangles, notes) of a pyvista data set: its outer surface where it is
    not a ``PolyData``, polygons triangulated by pyvista (the notes say both)."""
    import pyvista as pv

    notes = []
    if not isinstance(data, pv.PolyData):
        try:  # the algorithm named: pyvista 0.47+ warns that its default will change
            data = data.extract_surface(algorithm="dataset_surface")
        except TypeError:  # an older pyvista, which has only this one
            data = data.extract_surface()
        notes.append("the data set's outer surface is used")
    if data.n_cells and not data.is_all_triangles:
        data = data.triangulate()
        notes.append("polygons were triangulated (the vertices are kept as they are)")
    faces = np.asarray(data.faces).reshape(-1, 4)[:, 1:] if data.n_cells else np.zeros((0, 3))
    return np.asarray(data.points, dtype=np.float64), faces.astype(np.int64), notes


def read_file(path, strict: bool = True) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Every vertex of a mesh file in its order, the triangles and the damage notes."""
    path = Path(path)
    ext = path.suffix.lower()
    by_meshio = ext not in SUPPORTED_EXTENSIONS and ext in _meshio_extensions()
    if ext not in SUPPORTED_EXTENSIONS and not by_meshio:
        raise MeshError(
            f"{path.name}: unsupported file type '{ext or '(none)'}'; "
            f"open one of {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    if not path.is_file():
        raise MeshError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise MeshError(f"{path.name}: the file is empty")
    kind = "mesh" if by_meshio else ext[1:].upper()
    try:
        if by_meshio:
            import meshio

            vertices, faces, notes = meshio_arrays(meshio.read(path))
        elif ext in (".vtk", ".vtp"):
            with extra_needed(f"reading {ext} files"):
                import pyvista as pv

            vertices, faces, notes = pyvista_arrays(pv.read(str(path)))
        else:
            found = read_mesh_file(path, strict=strict)
            vertices, faces, notes = found.vertices, found.faces, found.notes
    except (MeshError, MissingExtraError):
        raise
    except (Exception, SystemExit) as exc:  # a parser may raise anything (meshio even exit)
        said = f" (meshio: {exc})" if by_meshio and isinstance(exc, Exception) and str(exc) else ""
        raise MeshError(
            f"{path.name}: could not be read as a {kind} file{said}; "
            "the file may be damaged, truncated or of another type"
        ) from None
    if len(vertices) == 0:
        raise MeshError(
            f"{path.name}: no vertices found in this {kind} file; "
            "the file may be damaged, truncated or of another type"
        )
    return vertices, faces, notes


AMBIGUOUS_EXTENSIONS = (".dat", ".xml", ".svg", ".node", ".ele", ".wkt", ".txt")
"""Extensions meshio reads that other files use too: a folder searched for meshes
(``batch``) leaves them out; a file named as a source is read as a mesh."""


def is_mesh_file(path, in_folder: bool = False) -> bool:
    """Whether :func:`load_mesh` reads ``path``'s extension (``in_folder``: a folder's search,
    without :data:`AMBIGUOUS_EXTENSIONS`)."""
    name = Path(path).name.lower()
    extensions = SUPPORTED_EXTENSIONS + _meshio_extensions()
    if in_folder:
        extensions = tuple(e for e in extensions if e not in AMBIGUOUS_EXTENSIONS)
    return any(name.endswith(e) for e in extensions)


def _meshio_extensions() -> tuple[str, ...]:
    """The extensions meshio reads, () without meshio."""
    try:
        import meshio
    except ImportError:
        return ()
    return tuple(meshio.extension_to_filetypes)


def meshio_arrays(m) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(vertices, triangles, notes) of a ``meshio.Mesh``: its triangle cells, quads and
    polygons fanned into triangles, other cells skipped (the notes say so)."""
    triangles, notes = [], []
    for block in m.cells:
        data = np.asarray(block.data)
        if block.type == "triangle":
            triangles.append(data)
        elif block.type in ("quad", "polygon") or block.type.startswith("polygon"):
            fan = range(1, data.shape[1] - 1)  # from each polygon's first vertex
            triangles.append(np.concatenate([data[:, [0, i, i + 1]] for i in fan]))
            notes.append(f"{len(data)} {block.type} cells were triangulated")
        elif block.type not in ("vertex", "line"):
            notes.append(f"{len(data)} {block.type} cells are not surface cells and were skipped")
    faces = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64)
    points = np.asarray(m.points, dtype=np.float64)
    if points.ndim == 2 and points.shape[1] == 2:  # a planar mesh: z = 0
        points = np.column_stack([points, np.zeros(len(points))])
    return points, faces.astype(np.int64), notes


def load_mesh(path, repair: bool = True, strict: bool = True) -> Mesh:
    """The triangle mesh of the file ``path``: OBJ, OFF, PLY, STL, VTK/VTP, or any surface
    format meshio reads; :class:`MeshError` naming the problem for a file that cannot be
    a surface.

    With ``repair=True`` (default) the arrays are repaired as by
    :func:`~modalviewer.core.cleaning.repair_mesh` and ``mesh.report`` says what was
    done; slivers are left (:func:`modalviewer.fix_slivers` removes them).  With
    ``repair=False`` they are only validated.  Vertex i is the file's vertex i either
    way.  A damaged file (:mod:`modalviewer.readers`) raises :class:`MeshError` naming
    the line or element, unless ``strict=False``: then the whole records are loaded and
    ``mesh.report`` says what was dropped.
    """
    path = Path(path)
    vertices, faces, notes = read_file(path, strict=strict)
    return mesh_from_arrays(vertices, faces, path.name, repair=repair, notes=notes)


def mesh_from_arrays(vertices, faces, source: str, repair: bool = True, notes=()) -> Mesh:
    """The :class:`Mesh` of raw arrays as :func:`load_mesh` makes it, ``notes`` in its report."""
    vertices = np.asarray(vertices)
    if len(faces) == 0:
        raise MeshError(
            f"{source}: the file contains {_plural(len(vertices), 'vertex')} "
            "but no faces: a point cloud is not a surface (reconstruct a surface from it "
            "first), or the file is truncated before its faces"
        )
    try:
        if repair:
            mesh = repair_mesh(vertices, faces, source=source)
        else:  # the report says what was not looked at, never "no problems found"
            mesh = Mesh(vertices, faces, report=MeshReport(source=source))
            mesh.report.add(shape_summary(mesh))
            mesh.report.add(
                "Not repaired (repair=False): duplicate vertices, face orientation and "
                "unused vertices are as in the file."
            )
    except MeshError as exc:
        if str(exc).startswith(source + ":"):
            raise
        raise MeshError(f"{source}: {exc}") from None
    for note in notes:  # as a sentence
        mesh.report.add(note[0].upper() + note[1:] + ("" if note.endswith(".") else "."))
    return mesh
