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


_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def strips_to_triangles(strip: np.ndarray) -> np.ndarray:
    """(m, 3) triangles of a triangle strip (-1 restarts), alternate ones flipped."""
    tris = []
    for run in np.split(strip, np.flatnonzero(strip < 0)):
        run = run[run >= 0]
        for i in range(len(run) - 2):
            a, b, c = run[i], run[i + 1], run[i + 2]
            tris.append((a, b, c) if i % 2 == 0 else (b, a, c))
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def _read_ply_tristrips(path: Path):
    """PLY files whose faces come as ``element tristrips`` (which trimesh and VTK skip)."""
    data = path.read_bytes()
    end = data.find(b"end_header")
    if end < 0:
        raise MeshError(f"{path.name}: not a PLY file (no end_header)")
    header = data[:end].decode("ascii", "replace").splitlines()
    body = data[data.index(b"\n", end) + 1 :]
    fmt = next(line.split()[1] for line in header if line.startswith("format"))
    elements: list[list] = []
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            elements.append([words[1], int(words[2]), []])
        elif words[:1] == ["property"] and elements:
            elements[-1][2].append(words[1:])
    if fmt != "binary_little_endian" and fmt != "binary_big_endian":
        tokens = body.split()
        pos = 0
    order = "<" if fmt == "binary_little_endian" else ">"
    vertices, strips = None, []
    offset = 0
    for name, count, props in elements:
        if name == "vertex":
            names = [p[-1] for p in props]
            if fmt.startswith("binary"):
                dtype = np.dtype([(p[-1], order + _PLY_TYPES[p[0]]) for p in props])
                arr = np.frombuffer(body, dtype=dtype, count=count, offset=offset)
                offset += dtype.itemsize * count
                vertices = np.column_stack([arr[c].astype(np.float64) for c in "xyz"])
            else:
                table = np.array(tokens[pos : pos + count * len(props)], dtype=np.float64)
                pos += count * len(props)
                table = table.reshape(count, len(props))
                vertices = table[:, [names.index(c) for c in "xyz"]]
        elif name == "tristrips":
            _, count_type, index_type, _ = props[0]
            for _ in range(count):
                if fmt.startswith("binary"):
                    ct = np.dtype(order + _PLY_TYPES[count_type])
                    it = np.dtype(order + _PLY_TYPES[index_type])
                    n = int(np.frombuffer(body, ct, 1, offset)[0])
                    offset += ct.itemsize
                    strips.append(np.frombuffer(body, it, n, offset).astype(np.int64))
                    offset += it.itemsize * n
                else:
                    n = int(tokens[pos])
                    strips.append(np.array(tokens[pos + 1 : pos + 1 + n], dtype=np.int64))
                    pos += n + 1
        else:
            raise MeshError(f"{path.name}: PLY element '{name}' before the faces is not supported")
    if vertices is None:
        raise MeshError(f"{path.name}: the PLY file has no vertices")
    faces = [strips_to_triangles(s) for s in strips]
    return vertices, np.vstack(faces) if faces else np.zeros((0, 3), dtype=np.int64)


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
        vertices, faces = _read_trimesh(path)
        if ext == ".ply" and len(faces) == 0 and b"tristrips" in path.read_bytes()[:4096]:
            return _read_ply_tristrips(path)
        if len(vertices) == 0:
            raise MeshError(
                f"{path.name}: no vertices found in this {ext[1:].upper()} file; "
                "the file may be damaged, truncated or of another type"
            )
        return vertices, faces
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

    With ``repair=True`` (default) duplicate vertices are merged, zero-area faces
    collapsed (a closed surface stays closed), faces repeating a vertex, duplicate faces
    and unreferenced vertices removed, and the orientation made consistent;
    ``mesh.report`` says what was done.  Nearly degenerate triangles (slivers) are left
    as they are: :func:`modalviewer.fix_slivers` removes them.  With ``repair=False`` the arrays
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
