"""Reading meshes from files, with repair and a report (OBJ, PLY, STL, OFF, VTK, VTP).

OBJ, PLY, STL and OFF are read with trimesh (no processing; repair is ours).  VTK and
VTP files are read with pyvista, imported only when such a file is opened, so that
``import modalviewer`` stays free of VTK.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .core.mesh import Mesh, MeshError, MeshReport, repair_mesh

__all__ = ["load_mesh", "read_arrays", "SUPPORTED_EXTENSIONS"]

SUPPORTED_EXTENSIONS = (".obj", ".ply", ".stl", ".off", ".vtk", ".vtp")


def _read_trimesh(path: Path):
    import trimesh

    loaded = trimesh.load(str(path), process=False, skip_materials=True)
    if isinstance(loaded, trimesh.Scene):
        geometries = list(loaded.dump()) if loaded.geometry else []
    else:
        geometries = [loaded]
    vertices, faces, offset = [], [], 0
    for geom in geometries:
        v = np.asarray(getattr(geom, "vertices", np.zeros((0, 3))), dtype=np.float64)
        f = np.asarray(getattr(geom, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
        vertices.append(v.reshape(-1, 3))
        faces.append(f + offset)
        offset += len(v)
    if not vertices:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.vstack(vertices), np.vstack(faces)


def _read_vtk(path: Path):
    import pyvista as pv

    data = pv.read(str(path))
    if not isinstance(data, pv.PolyData):
        data = data.extract_surface()
    data = data.triangulate()
    faces = np.asarray(data.faces).reshape(-1, 4)[:, 1:] if data.n_cells else np.zeros((0, 3))
    return np.asarray(data.points, dtype=np.float64), np.asarray(faces, dtype=np.int64)


def read_arrays(path) -> tuple[np.ndarray, np.ndarray]:
    """Raw (vertices (n, 3), faces (m, 3)) of a mesh file, polygons triangulated."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in SUPPORTED_EXTENSIONS:
        raise MeshError(
            f"{path.name}: unsupported file type '{ext or '(none)'}'; "
            f"open one of {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    if not path.is_file():
        raise MeshError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise MeshError(f"{path.name}: the file is empty")
    try:
        if ext in (".vtk", ".vtp"):
            return _read_vtk(path)
        return _read_trimesh(path)
    except MeshError:
        raise
    except Exception as exc:  # parsers raise anything on damaged files
        detail = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MeshError(
            f"{path.name}: could not be read as {ext[1:].upper()} ({detail[:200]}); "
            "the file may be damaged, truncated or of another type"
        ) from None


def load_mesh(path, repair: bool = True) -> Mesh:
    """Read a triangle mesh from ``path``.

    With ``repair=True`` (default) duplicate vertices are merged, degenerate and
    duplicate faces and unreferenced vertices removed, and the orientation made
    consistent; ``mesh.report`` says what was done.  With ``repair=False`` the arrays
    are validated as they are.

    Raises
    ------
    MeshError
        With a message naming the problem, for files that cannot be a surface.
    """
    path = Path(path)
    vertices, faces = read_arrays(path)
    if repair:
        return repair_mesh(vertices, faces, source=path.name)
    try:
        return Mesh(vertices, faces, report=MeshReport(source=path.name))
    except MeshError as exc:
        raise MeshError(f"{path.name}: {exc}") from None
