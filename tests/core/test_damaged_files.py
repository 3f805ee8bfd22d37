"""Damaged files: each gives the file's exact mesh, or a clear error naming the place,
or (where the damage cannot be told from a whole file) a report saying what is doubtful;
never a silently partial mesh.  Vertex i of what is read is vertex i of the file."""

import struct

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import grid_plate
from modalviewer.io import read_file
from modalviewer.readers import DamagedFileError


def _plate():
    plate = grid_plate(12, 12)
    v = np.array(plate.vertices)
    v[:, 2] = 0.1 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1])
    return v, np.array(plate.faces)


def _obj(v, f):
    lines = [f"v {a:.17g} {b:.17g} {c:.17g}" for a, b, c in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    return ("\n".join(lines) + "\n").encode()


def _off(v, f, n_faces=None):
    lines = ["OFF", f"{len(v)} {len(f) if n_faces is None else n_faces} 0"]
    lines += [f"{a:.17g} {b:.17g} {c:.17g}" for a, b, c in v]
    lines += [f"3 {a} {b} {c}" for a, b, c in f]
    return ("\n".join(lines) + "\n").encode()


def _ply_header(kind, n_v, n_f):
    return (
        f"ply\nformat {kind} 1.0\nelement vertex {n_v}\nproperty double x\n"
        f"property double y\nproperty double z\nelement face {n_f}\n"
        "property list uchar int vertex_indices\nend_header\n"
    ).encode()


def _ply_ascii(v, f, n_faces=None):
    body = [f"{a:.17g} {b:.17g} {c:.17g}" for a, b, c in v]
    body += [f"3 {a} {b} {c}" for a, b, c in f]
    header = _ply_header("ascii", len(v), len(f) if n_faces is None else n_faces)
    return header + ("\n".join(body) + "\n").encode()


def _ply_binary(v, f, n_faces=None):
    header = _ply_header("binary_little_endian", len(v), len(f) if n_faces is None else n_faces)
    body = np.asarray(v, "<f8").tobytes()
    row = np.dtype([("n", "u1"), ("i", "<i4", 3)])
    faces = np.zeros(len(f), row)
    faces["n"], faces["i"] = 3, f
    return header + body + faces.tobytes()


def _stl_binary(v, f, n_faces=None):
    tri = np.asarray(v, "<f4")[f]
    rows = np.zeros(len(f), np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rows["v"] = tri
    count = len(f) if n_faces is None else n_faces
    return b"\0" * 80 + struct.pack("<I", count) + rows.tobytes()


def _stl_ascii(v, f):
    out = ["solid plate"]
    for t in f:
        out += ["facet normal 0 0 1", "outer loop"]
        out += [f"vertex {a:.9g} {b:.9g} {c:.9g}" for a, b, c in v[t]]
        out += ["endloop", "endfacet"]
    out.append("endsolid plate")
    return ("\n".join(out) + "\n").encode()


FORMATS = {
    "obj": (".obj", _obj),
    "off": (".off", _off),
    "ply-ascii": (".ply", _ply_ascii),
    "ply-binary": (".ply", _ply_binary),
    "stl-binary": (".stl", _stl_binary),
    "stl-ascii": (".stl", _stl_ascii),
}
CUTS = (0.02, 0.2, 0.45, 0.5, 0.7, 0.9, 0.97, 0.999)


def _same_mesh(mesh, v, f, tol):
    """The loaded mesh is the plate: same size, area and vertex positions."""
    plate = mv.Mesh(v, f)
    return (
        mesh.n_vertices == len(v)
        and mesh.n_faces == len(f)
        and abs(mesh.total_area - plate.total_area) < tol * plate.total_area
    )


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_whole_file_gives_the_exact_mesh_and_no_doubt(tmp_path, fmt):
    v, f = _plate()
    ext, write = FORMATS[fmt]
    path = tmp_path / f"plate{ext}"
    path.write_bytes(write(v, f))
    mesh = mv.load_mesh(path)
    assert _same_mesh(mesh, v, f, 1e-6)
    assert "truncated" not in str(mesh.report) and "cut" not in str(mesh.report)
    if not fmt.startswith("stl"):  # STL stores each triangle's corners: merged at load
        vertices, faces, notes = read_file(path)
        tol = 0 if fmt in ("obj", "off", "ply-ascii", "ply-binary") else 1e-6
        assert np.max(np.abs(vertices - v)) <= tol and np.array_equal(faces, f)
        assert notes == []


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("cut", CUTS)
def test_a_truncated_file_is_an_error_or_says_it_may_be_cut(tmp_path, fmt, cut):
    v, f = _plate()
    ext, write = FORMATS[fmt]
    data = write(v, f)
    path = tmp_path / f"cut{ext}"
    path.write_bytes(data[: int(len(data) * cut)])
    try:
        mesh = mv.load_mesh(path)
    except mv.MeshError as exc:
        message = str(exc)
        assert message.startswith("cut" + ext), message
        assert "\n" not in message and len(message) < 400, message
        assert any(w in message for w in ("truncated", "ends", "incomplete", "damaged")), message
        return
    report = str(mesh.report)
    # loaded without error: the whole plate, or a report that says the file may be cut
    assert not _same_mesh(mesh, v, f, 1e-6), "a cut file cannot hold the whole plate"
    assert "may be" in report, (cut, report)


@pytest.mark.parametrize("fmt", ["off", "ply-ascii", "ply-binary", "stl-binary"])
def test_a_header_promising_more_faces_than_the_file_holds_is_named(tmp_path, fmt):
    v, f = _plate()
    ext, write = FORMATS[fmt]
    path = tmp_path / f"twice{ext}"
    path.write_bytes(write(v, f, n_faces=2 * len(f)))
    with pytest.raises(mv.MeshError, match=rf"^twice\{ext}: .*{len(f)} of the {2 * len(f)}"):
        mv.load_mesh(path)
    # strict=False loads what is there and says what was missing
    mesh = mv.load_mesh(path, strict=False)
    assert _same_mesh(mesh, v, f, 1e-6)
    assert f"{len(f)} of the {2 * len(f)}" in str(mesh.report)


@pytest.mark.parametrize("fmt", ["obj", "off", "ply-ascii", "ply-binary", "stl-binary"])
def test_strict_false_loads_the_complete_records_of_a_cut_file(tmp_path, fmt):
    v, f = _plate()
    ext, write = FORMATS[fmt]
    data = write(v, f)
    path = tmp_path / f"cut{ext}"
    path.write_bytes(data[: int(len(data) * 0.9)])
    mesh = mv.load_mesh(path, strict=False)
    assert 0 < mesh.n_faces < len(f)
    assert "face" in str(mesh.report) or "triangle" in str(mesh.report)


def test_random_bytes_named_stl_are_refused_as_no_stl_strict_or_not(tmp_path):
    """4000 random bytes read as a binary STL: a header count of billions, records whose
    coordinates reach 3.4e38 or are not numbers.  Refused as no STL file whether or not
    the caller asks for a damaged file's whole records (they made a mesh of a few
    scattered triangles whose computation failed inside the solver), while a cut real
    STL of the same size still loads its whole records with strict=False."""
    data = np.random.default_rng(5).integers(0, 256, 4000, dtype=np.uint8).tobytes()
    path = tmp_path / "random.stl"
    path.write_bytes(data)
    announced = int(np.frombuffer(data, "<u4", 1, 80)[0])
    for strict in (True, False):
        with pytest.raises(mv.MeshError, match=r"^random\.stl: not an STL file: .*") as err:
            mv.load_mesh(path, strict=strict)
        assert not isinstance(err.value, DamagedFileError)  # no "Open anyway"
        assert f"announces {announced} triangles where 4000 bytes hold 78" in str(err.value)
    v, f = _plate()
    cut = tmp_path / "cut.stl"
    cut.write_bytes(_stl_binary(v, f)[:4000])
    with pytest.raises(DamagedFileError):
        mv.load_mesh(cut)
    assert mv.load_mesh(cut, strict=False).n_faces == 78


def test_a_face_naming_a_missing_vertex_is_named_by_line(tmp_path):
    v, f = _plate()
    text = _obj(v, f).decode().replace(f"f {f[3][0] + 1} ", "f 9999 ", 1)
    path = tmp_path / "bad.obj"
    path.write_text(text)
    line = len(v) + 4
    with pytest.raises(mv.MeshError, match=rf"^bad\.obj: line {line}: .*vertex 9998"):
        mv.load_mesh(path)
    mesh = mv.load_mesh(path, strict=False)
    assert mesh.n_faces == len(f) - 1 and f"line {line}" in str(mesh.report).lower()


def test_an_obj_record_cut_mid_line_is_named(tmp_path):
    v, f = _plate()
    lines = _obj(v, f).decode().splitlines()
    lines[5] = "v 0.25"
    path = tmp_path / "half.obj"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(mv.MeshError, match=r"^half\.obj: line 6: the vertex record 'v 0.25'"):
        mv.load_mesh(path)


@pytest.mark.parametrize("ending", ["f ", "f", "f \n", "f 3 "])
def test_an_obj_cut_just_after_a_face_records_f_is_refused(tmp_path, ending):
    # a file cut after "f " loaded as the faces before it, without a word (the fast
    # reader's splitlines() dropped the empty last record)
    v, f = _plate()
    text = _obj(v, f[:100]).decode() + ending
    path = tmp_path / "cut.obj"
    path.write_text(text)
    line = len(v) + 101
    with pytest.raises(mv.MeshError, match=rf"^cut\.obj: line {line}: the face record"):
        mv.load_mesh(path)
    mesh = mv.load_mesh(path, strict=False)
    assert mesh.n_faces == 100 and f"line {line}: the face record" in str(mesh.report).lower()


@pytest.mark.parametrize("fmt", ["obj", "off", "ply-ascii", "ply-binary"])
@pytest.mark.parametrize("where", ["before", "between", "after"])
def test_unused_vertices_keep_the_files_numbering(tmp_path, fmt, where):
    v, f = _plate()
    extra = np.array([[7.0, 7.0, 7.0], [8.0, 8.0, 8.0], [9.0, 9.0, 9.0]])
    at = {"before": 0, "between": len(v) // 2, "after": len(v)}[where]
    v_file = np.vstack([v[:at], extra, v[at:]])
    f_file = np.where(f >= at, f + len(extra), f)
    ext, write = FORMATS[fmt]
    path = tmp_path / f"unused{ext}"
    path.write_bytes(write(v_file, f_file))
    vertices, faces, notes = read_file(path)
    assert len(vertices) == len(v_file) and np.array_equal(faces, f_file)
    assert np.array_equal(vertices[at : at + 3], extra)
    mesh = mv.load_mesh(path)
    assert "3 vertices used by no face" in str(mesh.report)
    np.testing.assert_array_equal(mesh.unused, np.arange(at, at + 3))
    np.testing.assert_array_equal(mesh.vertices, v_file)


def test_an_obj_ending_in_a_face_record_with_unused_vertices_may_be_truncated(tmp_path):
    v, f = _plate()
    body = [f"v {x} {y} {z}" for x, y, z in np.vstack([v, [[7.0, 7.0, 7.0]]])]
    body += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    cut = tmp_path / "cut.obj"
    cut.write_text("\n".join(body) + "\n")
    complete = tmp_path / "complete.obj"
    complete.write_text("\n".join(body) + "\n# End of File\n")
    assert "it may be truncated" in str(mv.load_mesh(cut).report)
    assert "truncated" not in str(mv.load_mesh(complete).report)


@pytest.mark.parametrize("fmt", ["obj", "off", "ply-ascii"])
def test_strict_false_keeps_the_numbers_after_an_incomplete_vertex_record(tmp_path, fmt):
    v, f = _plate()
    ext, write = FORMATS[fmt]
    data = write(v, f).decode()
    broken = 20  # vertex 20's record loses its last two numbers
    record = {"obj": "v {:.17g} {:.17g} {:.17g}", "off": "{:.17g} {:.17g} {:.17g}"}.get(
        fmt, "{:.17g} {:.17g} {:.17g}"
    )
    whole = record.format(*v[broken])
    assert data.count(whole) == 1
    data = data.replace(whole, whole.rsplit(" ", 2)[0])
    path = tmp_path / f"broken{ext}"
    path.write_text(data)
    with pytest.raises(mv.MeshError, match="incomplete"):
        mv.load_mesh(path)
    vertices, faces, notes = read_file(path, strict=False)
    assert len(vertices) == len(v)  # every later vertex keeps its number
    others = np.arange(len(v)) != broken
    assert np.array_equal(vertices[others], v[others])
    using = np.any(f == broken, axis=1)
    assert np.array_equal(faces, f[~using])
    mesh = mv.load_mesh(path, strict=False)
    assert mesh.n_faces == len(f) - using.sum()
    assert mesh.n_vertices == len(v)  # the input's numbering: vertex 20 has no value
    assert mesh.solver_mesh.n_vertices == len(np.unique(f[~using]))
    assert broken in mesh.unused
    assert f"{using.sum()} faces using a vertex whose record was incomplete dropped" in str(
        mesh.report
    )


@pytest.mark.parametrize("strict", [True, False])
def test_an_image_renamed_obj_is_called_not_an_obj_file(tmp_path, strict):
    from PIL import Image

    png = tmp_path / "picture.png"
    Image.fromarray(np.random.default_rng(0).integers(0, 255, (64, 64, 3), np.uint8)).save(png)
    path = tmp_path / "picture.obj"
    path.write_bytes(png.read_bytes())
    with pytest.raises(mv.MeshError, match=r"^picture\.obj: not an OBJ file: it holds binary"):
        mv.load_mesh(path, strict=strict)
