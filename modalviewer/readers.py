"""Strict readers of OBJ, PLY (ASCII and binary), OFF and STL files.

Each reader returns every vertex of the file in its order (vertex ``i`` is the file's
vertex ``i``, used by a face or not) and the faces as triangles (polygons fanned).
Damage is detected rather than loaded: a record cut in the middle, element counts the
data do not fill, faces naming vertices the file does not have.  With ``strict=True``
each raises :class:`~modalviewer.core.mesh.MeshError` naming the file, the line or
element and what is missing; with ``strict=False`` what could be read is returned and
``notes`` says what was dropped (vertices no face uses get a note, since a file cut
between face records leaves them behind).  Well-formed files are parsed by numpy in one
go; anything else goes to the record-by-record reader, which names the damage.  These
checks are why the readers are the package's own: trimesh loads an OBJ cut short
without a word and refuses a cut PLY without saying where.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from .core.mesh import MeshError, _plural


class DamagedFileError(MeshError):
    """A file of its format, damaged or truncated: ``load_mesh(path, strict=False)``
    loads its complete records (the viewer offers this as "Open anyway", the command
    line as ``--partial``).  ``detail`` is the message without that advice, for callers
    that give their own."""

    def __init__(self, detail: str):
        super().__init__(
            detail + "; the file is damaged or truncated "
            "(load_mesh(path, strict=False) or 'Open anyway' loads what is there)"
        )
        self.detail = detail


@dataclass
class MeshFile:
    """What a reader found: all vertices (n, 3), triangles (m, 3) and notes on damage."""

    vertices: np.ndarray
    faces: np.ndarray
    notes: list[str] = field(default_factory=list)


class _Damage:
    """Collects problems: raises the first one when strict, else keeps it as a note."""

    def __init__(self, name: str, strict: bool):
        self.name, self.strict, self.notes = name, strict, []

    def __call__(self, where: str, what: str) -> None:
        message = f"{self.name}: {where}: {what}"
        if self.strict:
            raise DamagedFileError(message)
        self.notes.append(f"{where}: {what}")

    def ends_early(self, where: str, read: int, announced: str) -> None:
        """The data end after ``read`` of the ``announced`` records ("128 faces")."""
        self(where, f"the file ends after {read} of the {announced} its header announces")

    def note(self, where: str, what: str) -> None:
        """A doubt that is no error: kept in the notes, strict or not."""
        self.notes.append(f"{where}: {what}")


def _check_last_line(text: str, damage: _Damage, record, first: int = 1) -> None:
    """A text whose last record has no line break may have been cut inside it (``first``:
    the file's number of the text's first line)."""
    stripped = text.rstrip(" \t")
    if stripped and not stripped.endswith(("\n", "\r")):
        last = stripped.splitlines()[-1].strip()
        if last and not last.startswith("#") and (record == "" or last.split()[0] in record):
            damage.note(
                f"line {stripped.count(chr(10)) + first}",
                f"the file ends inside the record '{last[:40]}' without a line break: "
                "it may be cut there, and that record may be wrong",
            )


def _mesh_file(vertices, polygons: list, unplaced: list, damage: _Damage, place) -> MeshFile:
    """The vertices (every record, in the file's order) and the polygons fanned into
    triangles, less the faces with fewer than three corners or naming a vertex the file
    does not have (each reported at ``place(i)``) and, with ``strict=False``, those using
    one of the ``unplaced`` vertices, whose records were incomplete.  Those vertices stay,
    used by no face, so that the vertices after them keep the file's numbers; they are
    put outside the bounding box of the others, where no repair can take them for a
    duplicate of a real vertex."""
    vertices = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    n, kept = len(vertices), []
    for i, face in enumerate(polygons):
        bad = [j for j in face if j < 0 or j >= n]
        if len(face) < 3:
            damage(place(i), "the face has fewer than three corners")
        elif bad:
            damage(
                place(i),
                f"the face names vertex {bad[0]} but the file has only "
                f"{_plural(n, 'vertex')} (numbered from 0)",
            )
        else:
            kept.append(face)
    if unplaced:
        placed = np.delete(vertices, unplaced, axis=0)
        if len(placed):
            low, high = placed.min(axis=0), placed.max(axis=0)
            outside = high + (high - low).max() + 1.0
        else:
            outside = np.zeros(3)
        vertices[unplaced] = outside + np.arange(len(unplaced))[:, None]
        incomplete = set(unplaced)
        whole = [p for p in kept if incomplete.isdisjoint(p)]
        if len(whole) < len(kept):
            dropped = _plural(len(kept) - len(whole), "face")
            damage.note("faces", f"{dropped} using a vertex whose record was incomplete dropped")
        kept = whole
    triangles = [(p[0], p[i], p[i + 1]) for p in kept for i in range(1, len(p) - 1)]  # fanned
    return MeshFile(vertices, np.array(triangles, dtype=np.int64).reshape(-1, 3), damage.notes)


def _numbers(rows: list[str], width: int, dtype) -> np.ndarray | None:
    """(len(rows), width) numbers of rows of ``width`` numbers each, parsed by numpy in one
    go; None otherwise (the record-by-record reader then finds and names the problem)."""
    if any(len(row.split()) != width for row in rows):
        return None
    try:
        return np.array(" ".join(rows).split(), dtype=dtype).reshape(len(rows), width)
    except ValueError:
        return None


# --------------------------------------------------------------------------- OBJ


def _read_obj_fast(text: str) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices and triangles of a well-formed OBJ of triangles, or None for any other file
    (which the line-by-line reader then reads and checks)."""
    lines = text.splitlines()
    if any(line.rstrip() in ("v", "f") for line in lines):  # a bare record: cut there
        return None
    v_rows = [line[2:] for line in lines if line[:2] == "v "]
    f_rows = [line[2:] for line in lines if line[:2] == "f "]
    face_text = "\n".join(f_rows)
    if "/" in face_text:
        face_text = re.sub(r"/\S*", "", face_text)
    width = len(v_rows[0].split()) if v_rows else 0  # x y z, maybe w or r g b after
    vertices = _numbers(v_rows, width, np.float64) if width >= 3 else None
    # split on "\n", not splitlines(): a record cut right after "f " stays a row
    faces = _numbers(face_text.split("\n"), 3, np.int64) if f_rows else np.ones((0, 3), int)
    if vertices is None or faces is None:
        return None
    faces = faces - 1
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        return None
    return np.ascontiguousarray(vertices[:, :3]), faces


def _read_obj(path: Path, strict: bool) -> MeshFile:
    damage = _Damage(path.name, strict)
    data = path.read_bytes()
    if b"\0" in data[:4096]:  # an OBJ file is text, which has no NUL bytes
        raise MeshError(
            f"{path.name}: not an OBJ file: it holds binary data (a file of another type, "
            "such as an image, with the name of a mesh file?)"
        )
    text = data.decode("utf-8", "replace")
    _check_last_line(text, damage, ("v", "f"))
    fast = _read_obj_fast(text)
    result = _obj_records(text, damage) if fast is None else MeshFile(*fast, damage.notes)
    unused = int((np.bincount(result.faces.ravel(), minlength=len(result.vertices)) == 0).sum())
    # a file cut between two face records ends in a face record and leaves vertices no
    # face uses; one that ends in a comment ("# End of File") or another record does not
    tail = [line.strip() for line in text[-4096:].splitlines() if line.strip()]
    if unused and len(result.faces) and tail[-1].startswith(("f ", "f\t")):
        result.notes.append(
            f"the file ends with a face record and {_plural(unused, 'vertex')} "
            f"of it {'is' if unused == 1 else 'are'} used by no face: it may be truncated (a "
            "file cut between two face records leaves such vertices)"
        )
    return result


def _obj_records(text: str, damage: _Damage) -> MeshFile:
    vertices: list = []
    unplaced: list = []
    polygons: list = []
    face_lines: list = []
    for number, line in enumerate(text.splitlines(), start=1):
        record = line.rstrip()  # "v" or "f" alone: a record cut after its letter
        if line[:2] == "v " or line[:2] == "v\t" or record == "v":
            words = line.split()
            try:
                xyz = [float(w) for w in words[1:4]]
            except ValueError:
                xyz = []
            if len(xyz) < 3:
                damage(f"line {number}", f"the vertex record '{line.strip()[:40]}' is incomplete")
                unplaced.append(len(vertices))
                xyz = [np.nan] * 3
            vertices.append(xyz)
        elif line[:2] == "f " or line[:2] == "f\t" or record == "f":
            words = line.split()[1:]
            try:
                corners = [int(w.split("/")[0]) for w in words]
            except ValueError:
                corners = []
            if len(corners) < 3:
                damage(f"line {number}", f"the face record '{line.strip()[:40]}' is incomplete")
                continue
            n = len(vertices)
            # OBJ numbers from 1; negative numbers count back from the last vertex read
            polygons.append([c - 1 if c > 0 else n + c for c in corners])
            face_lines.append(number)
    return _mesh_file(vertices, polygons, unplaced, damage, lambda i: f"line {face_lines[i]}")


# --------------------------------------------------------------------------- OFF


def _read_off(path: Path, strict: bool) -> MeshFile:
    """An OFF file is read as an ASCII PLY of its vertex and face elements, after its
    header: "OFF" and the counts, on one line or two, comments allowed."""
    lines = path.read_bytes().decode("utf-8", "replace").splitlines(keepends=True)
    head: list[str] = []
    start = 0
    while len(head) < 3 and start < len(lines):
        head += lines[start].split("#", 1)[0].split()
        start += 1
    if not head or not head[0].upper().endswith("OFF"):
        raise MeshError(f"{path.name}: not an OFF file (the first line is not 'OFF')")
    if len(head) < 3:
        raise MeshError(f"{path.name}: the OFF file ends before its vertex and face counts")
    try:
        n_vertices, n_faces = int(head[1]), int(head[2])
    except ValueError:
        raise MeshError(f"{path.name}: the OFF counts line is not 'vertices faces edges'") from None
    elements = [
        ("vertex", n_vertices, [(c, ["double"]) for c in "xyz"]),
        ("face", n_faces, [("vertex_indices", ["list", "uchar", "int"])]),
    ]
    body = "".join(lines[start:])
    return _read_ascii(path, elements, body, start + 1, _Damage(path.name, strict))


# --------------------------------------------------------------------------- PLY

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip

_FACE_LISTS = ("vertex_indices", "vertex_index")


def strips_to_triangles(strip: np.ndarray) -> np.ndarray:
    """(m, 3) triangles of a triangle strip (-1 restarts), alternate ones flipped."""
    tris = []
    for run in np.split(strip, np.flatnonzero(strip < 0)):
        run = run[run >= 0]
        for i in range(len(run) - 2):
            a, b, c = run[i], run[i + 1], run[i + 2]
            tris.append((a, b, c) if i % 2 == 0 else (b, a, c))
    return np.array(tris, dtype=np.int64).reshape(-1, 3)


def _ply_header(path: Path, data: bytes):
    if not data.startswith(b"ply"):
        raise MeshError(f"{path.name}: not a PLY file (it does not start with 'ply')")
    end = data.find(b"end_header")
    if end < 0:
        raise MeshError(f"{path.name}: the PLY header is truncated or damaged (no 'end_header')")
    newline = data.find(b"\n", end)
    body = data[newline + 1 :] if newline >= 0 else b""
    fmt, elements = None, []
    for line in data[:end].decode("ascii", "replace").splitlines():
        words = line.split()
        if words[:1] == ["format"] and len(words) > 1:
            fmt = words[1]
        elif words[:1] == ["element"] and len(words) == 3:
            try:
                elements.append((words[1], int(words[2]), []))
            except ValueError:
                raise MeshError(f"{path.name}: the PLY header line '{line}' has no count") from None
        elif words[:1] == ["property"] and elements:
            types = words[1:-1]
            bad = [t for t in types if t != "list" and t not in _PLY_TYPES]
            if bad or not types:
                raise MeshError(f"{path.name}: the PLY property '{line.strip()}' is not understood")
            elements[-1][2].append((words[-1], types))
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise MeshError(f"{path.name}: the PLY format '{fmt}' is not understood")
    return fmt, elements, body


def _ply_binary(body, order, damage, name, count, props, offset):
    """Rows of one binary element: a dict of columns; the offset after it; rows read."""
    if all(types[0] != "list" for _, types in props):
        dtype = np.dtype([(p, order + _PLY_TYPES[t[0]]) for p, t in props])
        available = (len(body) - offset) // dtype.itemsize if dtype.itemsize else count
        rows = min(count, max(available, 0))
        if rows < count:
            damage.ends_early(f"element '{name}' {rows}", rows, f"{count} {name} elements")
        arr = np.frombuffer(body, dtype=dtype, count=rows, offset=offset)
        return {p: arr[p] for p, _ in props}, offset + dtype.itemsize * rows, rows
    # elements with lists: a fast path for the usual 'list uchar int' of triangles only
    if len(props) == 1:
        _, (_, count_type, item_type) = props[0]
        ct, it = np.dtype(order + _PLY_TYPES[count_type]), np.dtype(order + _PLY_TYPES[item_type])
        row = np.dtype([("n", ct), ("i", it, 3)])
        if len(body) - offset >= row.itemsize * count:
            arr = np.frombuffer(body, dtype=row, count=count, offset=offset)
            if np.all(arr["n"] == 3):
                lists = arr["i"].astype(np.int64)
                return {props[0][0]: lists}, offset + row.itemsize * count, count
    columns: dict = {p: [] for p, _ in props}
    for i in range(count):
        row_values = {}
        try:  # np.frombuffer raises ValueError where the data end before the value
            for prop, types in props:
                it, n = np.dtype(order + _PLY_TYPES[types[-1]]), 1
                if types[0] == "list":
                    ct = np.dtype(order + _PLY_TYPES[types[1]])
                    n = int(np.frombuffer(body, ct, 1, offset)[0])
                    offset += ct.itemsize
                items = np.frombuffer(body, it, n, offset)
                row_values[prop] = items.astype(np.int64) if types[0] == "list" else items[0]
                offset += it.itemsize * n
        except ValueError:
            pass
        if len(row_values) < len(props):
            damage(
                f"element '{name}' {i}",
                f"the file ends in {name} element {i} of the {count} its header announces",
            )
            return columns, offset, i
        for prop in columns:
            columns[prop].append(row_values[prop])
    return columns, offset, count


def _ply_ascii(lines, damage, name, count, props, line_index):
    columns: dict = {p: [] for p, _ in props}
    for i in range(count):
        if line_index >= len(lines):
            damage.ends_early(f"element '{name}' {i}", i, f"{count} {name} elements")
            return columns, line_index, i
        number, words = lines[line_index]
        line_index += 1
        pos, row = 0, {}
        try:
            for prop, types in props:
                if types[0] == "list":
                    n = int(words[pos])
                    items = words[pos + 1 : pos + 1 + n]
                    if len(items) < n:
                        raise IndexError
                    row[prop] = np.array([int(float(w)) for w in items], dtype=np.int64)
                    pos += n + 1
                else:
                    row[prop] = float(words[pos])
                    pos += 1
        except (IndexError, ValueError):
            damage(
                f"line {number} ({name} element {i})",
                f"the {name} record is incomplete or not numbers",
            )
            row = dict.fromkeys(columns)  # a placeholder keeps the later rows' numbers
        for prop in columns:
            columns[prop].append(row[prop])
    return columns, line_index, count


def _ascii_fast(elements, body: str) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices and triangles of a well-formed ASCII body of vertices and triangles, or None
    for any other (which the record-by-record reader then reads and checks)."""
    if [name for name, _, _ in elements] != ["vertex", "face"] or "#" in body:
        return None
    (_, n, vertex_props), (_, m, face_props) = elements
    names = [prop for prop, _ in vertex_props]
    if any(types[0] == "list" for _, types in vertex_props) or not {"x", "y", "z"} <= set(names):
        return None
    if len(face_props) != 1 or face_props[0][0] not in _FACE_LISTS:
        return None
    rows = [row for row in body.splitlines() if row.strip()]
    if len(rows) != n + m:
        return None
    table = _numbers(rows[:n], len(names), np.float64)
    faces = _numbers(rows[n:], 4, np.int64)  # rows "3 a b c" of triangles
    if table is None or faces is None or not (faces[:, 0] == 3).all():
        return None
    faces = faces[:, 1:]
    if len(faces) and (faces.min() < 0 or faces.max() >= n):
        return None
    return np.ascontiguousarray(table[:, [names.index(c) for c in "xyz"]]), faces


def _read_ascii(path: Path, elements, body: str, first: int, damage: _Damage) -> MeshFile:
    """The elements of an ASCII PLY's or OFF's ``body``, starting at the file's line ``first``."""
    _check_last_line(body, damage, "", first)
    fast = _ascii_fast(elements, body)
    if fast is not None:
        return MeshFile(*fast, damage.notes)
    lines = []
    for number, line in enumerate(body.splitlines(), start=first):
        words = line.split("#", 1)[0].split()
        if words:
            lines.append((number, words))
    return _read_elements(path, elements, partial(_ply_ascii, lines, damage), damage)


def _read_ply(path: Path, strict: bool) -> MeshFile:
    damage = _Damage(path.name, strict)
    data = path.read_bytes()
    fmt, elements, body = _ply_header(path, data)
    if fmt == "ascii":
        first = data[: len(data) - len(body)].count(b"\n") + 1
        return _read_ascii(path, elements, body.decode("ascii", "replace"), first, damage)
    order = "<" if fmt == "binary_little_endian" else ">"
    return _read_elements(path, elements, partial(_ply_binary, body, order, damage), damage)


def _read_elements(path: Path, elements, read, damage: _Damage) -> MeshFile:
    """The mesh of a PLY's ``elements`` (name, count, properties), each read by
    ``read(name, count, properties, position)`` -> (columns, position after, rows read)."""
    cursor = 0
    vertices, polygons, unplaced = None, [], []
    for name, count, props in elements:
        columns, cursor, rows = read(name, count, props, cursor)
        if name == "vertex":
            missing = [c for c in "xyz" if c not in columns]
            if missing:
                raise MeshError(f"{path.name}: the PLY vertices have no '{missing[0]}' property")
            xs = columns["x"]  # an array is whole; None marks an incomplete ASCII record
            unplaced = [i for i, x in enumerate(xs) if x is None] if isinstance(xs, list) else []
            vertices = np.column_stack(
                [np.array(columns[c], dtype=np.float64).reshape(-1) for c in "xyz"]
            )
        elif name in ("face", "tristrips"):
            key = next((p for p, _ in props if p in _FACE_LISTS), None)
            if key is None:
                raise MeshError(f"{path.name}: the PLY {name} element has no vertex_indices list")
            lists = columns[key]
            if name == "tristrips":
                strips = [np.asarray(s) for s in lists if s is not None]
                polygons += [list(t) for s in strips for t in strips_to_triangles(s)]
            elif isinstance(lists, np.ndarray):
                polygons = lists  # the binary fast path's (m, 3) array
            else:
                polygons += [list(p) for p in lists if p is not None]
        if rows < count:
            break  # the data ended: no later element can be read
    if vertices is None:
        raise MeshError(f"{path.name}: the PLY file has no vertex element")
    if isinstance(polygons, np.ndarray):  # the binary fast path's (m, 3) triangles
        if len(polygons) == 0 or (polygons.min() >= 0 and polygons.max() < len(vertices)):
            return MeshFile(vertices, polygons, damage.notes)
        polygons = polygons.tolist()  # _mesh_file names each face naming no vertex
    return _mesh_file(vertices, polygons, unplaced, damage, lambda i: f"face {i}")


# --------------------------------------------------------------------------- STL


def _read_stl(path: Path, strict: bool) -> MeshFile:
    damage = _Damage(path.name, strict)
    data = path.read_bytes()
    binary_count = int(np.frombuffer(data, "<u4", 1, 80)[0]) if len(data) >= 84 else -1
    is_ascii = data.lstrip()[:5].lower() == b"solid" and len(data) != 84 + 50 * binary_count
    if not is_ascii:
        if binary_count < 0:
            raise MeshError(f"{path.name}: too short for a binary STL file ({len(data)} bytes)")
        rows = (len(data) - 84) // 50
        dtype = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
        arr = np.frombuffer(data, dtype=dtype, count=min(rows, binary_count), offset=84)
        if len(data) != 84 + 50 * binary_count:
            _refuse_implausible_stl(path.name, arr, binary_count, len(data))
        if rows < binary_count:
            damage.ends_early(f"triangle {rows}", rows, _plural(binary_count, "triangle"))
        corners = arr["v"].reshape(-1, 3).astype(np.float64)
        return MeshFile(*_stl_vertices(corners), damage.notes)
    corners, current, facet_line = [], [], 0  # three corners a facet, in the file's order
    lines = data.decode("ascii", "replace").splitlines()
    ended = False
    for number, line in enumerate(lines, start=1):
        words = line.split()
        if not words:
            continue
        key = words[0].lower()
        if key == "facet":
            current, facet_line = [], number
        elif key == "vertex":
            try:
                current.append([float(w) for w in words[1:4]])
                if len(current[-1]) < 3:
                    raise ValueError
            except ValueError:
                damage(f"line {number}", "the vertex record is incomplete")
                current.append(None)
        elif key == "endfacet":
            if len(current) != 3 or any(c is None for c in current):
                damage(f"line {facet_line}", "the facet does not have three whole vertices")
            else:
                corners += current
            current = []
        elif key == "endsolid":
            ended = True
    if not ended:
        damage(f"line {len(lines)}", "the file ends before 'endsolid'")
    return MeshFile(
        *_stl_vertices(np.array(corners, dtype=np.float64).reshape(-1, 3)), damage.notes
    )


def _stl_vertices(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, triangles) of an STL file's triangle corners (3 m, 3): STL names a
    vertex by its position only, so its vertices are the distinct corner positions in
    the order they first appear (vertex i is the i-th distinct one), found by one stable
    sort of the positions' bytes."""
    bits = np.ascontiguousarray(corners + 0.0, dtype=np.float64)  # + 0.0: -0.0 is 0.0
    _, first, group = np.unique(
        bits.view(np.dtype((np.void, 24))).ravel(), return_index=True, return_inverse=True
    )
    order = np.argsort(first)  # the distinct positions in the order they first appear
    rank = np.empty(len(first), dtype=np.int64)
    rank[order] = np.arange(len(first))
    return corners[first[order]], rank[group.reshape(-1)].reshape(-1, 3)


STL_COORDINATE_LIMIT = 1e30
"""A binary STL whose size does not match its header and whose records hold coordinates
beyond this (or not numbers) is not an STL file: real ones are in millimetres or
metres, while random bytes read as float32 reach 3.4e38 in about one value in ten."""


def _refuse_implausible_stl(name: str, arr: np.ndarray, announced: int, size: int) -> None:
    """Raise MeshError where a binary STL's records are not coordinates (random or other
    binary data with an extension .stl): opened anyway, they would make a mesh of a few
    scattered huge triangles whose computation fails inside the solver."""
    corners = arr["v"].reshape(-1, 9)
    bad = ~(np.isfinite(corners) & (np.abs(corners) <= STL_COORDINATE_LIMIT)).all(axis=1)
    if not bad.any():
        return
    first = int(np.flatnonzero(bad)[0])
    raise MeshError(
        f"{name}: not an STL file: its header announces "
        f"{_plural(announced, 'triangle')} where {size} bytes hold "
        f"{len(arr)}, and triangle {first + 1} has a coordinate that is not a number or "
        f"beyond {STL_COORDINATE_LIMIT:.0e}; check that this is the file you meant"
    )


READERS = {".obj": _read_obj, ".off": _read_off, ".ply": _read_ply, ".stl": _read_stl}


def read_mesh_file(path, strict: bool = True) -> MeshFile:
    """Vertices, triangles and damage notes of an OBJ, PLY, OFF or STL file (see the module
    docstring for ``strict``)."""
    path = Path(path)
    return READERS[path.suffix.lower()](path, strict)
