"""Issue 25, the whole path in the file's vertex numbers: a file with unused vertices
before, between and after the used ones and a duplicated vertex -> load -> pick (the
viewer model, no Qt) -> distance -> CLI CSV -> session -> field export.  Every number is
the file's, and every value is the one of the same mesh without the extra vertices."""

import json

import numpy as np
import pytest

from modalviewer.cli import main
from modalviewer.core.cache import SpectrumCache
from modalviewer.core.primitives import icosphere
from modalviewer.viewer import ViewerModel, wording
from modalviewer.viewer.session import restore_session, save_session

K = 20


def _write_ply(path, v, f):
    head = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(v)}",
        "property double x",
        "property double y",
        "property double z",
        f"element face {len(f)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    rows = [f"{x:.17g} {y:.17g} {z:.17g}" for x, y, z in v] + [f"3 {a} {b} {c}" for a, b, c in f]
    path.write_text("\n".join(head + rows) + "\n")
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """(padded file, compact file, file index of each compact vertex, duplicate index,
    unused file indices)."""
    tmp = tmp_path_factory.mktemp("numbering")
    base = icosphere(2)
    n, half = base.n_vertices, base.n_vertices // 2
    far = np.array([[5.0, 5.0, 5.0]])
    v = np.vstack([far, far + 1, base.vertices[:half], far + 2, base.vertices[half:]])
    v = np.vstack([v, base.vertices[[7]], far + 3])  # a duplicate of vertex 7, one unused
    where = np.concatenate([np.arange(half) + 2, np.arange(half, n) + 3])
    dup = len(v) - 2
    f = where[base.faces]
    faces_of_7 = np.flatnonzero((base.faces == 7).any(axis=1))[:2]
    f[faces_of_7] = np.where(f[faces_of_7] == where[7], dup, f[faces_of_7])
    unused = [0, 1, half + 2, len(v) - 1]
    padded = _write_ply(tmp / "padded.ply", v, f)
    compact = _write_ply(tmp / "compact.ply", base.vertices, base.faces)
    return padded, compact, where, dup, unused


def _model(tmp_path):
    return ViewerModel(cache=SpectrumCache(tmp_path / "cache"))


def _distance(model, path, pick_file_vertex):
    model.open_mesh(path)
    model.jobs.wait(model.request_spectrum("laplacian", k=K))
    model.state.set_pick_file_vertex(pick_file_vertex)
    model.state.set_display(kind="distance", distance_kind="hks")
    return model.state.derived.distance_map()


def test_load_pick_distance_in_file_numbers(files, tmp_path):
    padded, compact, where, dup, unused = files
    model = _model(tmp_path)
    pick = int(where[40])  # mesh vertex 40 is vertex where[40] of the padded file
    d = _distance(model, padded, pick)
    mesh = model.state.mesh
    assert mesh.n_file_vertices == len(where) + len(unused) + 1
    assert np.array_equal(mesh.file_vertices, where)
    assert model.state.picked == 40 and model.state.picked_file_vertex == pick
    assert f"from vertex {pick}" in wording.legend(model.state)

    ref = _distance(_model(tmp_path), compact, 40)
    np.testing.assert_allclose(d, ref, rtol=1e-9, atol=1e-12)
    field = mesh.to_file_field(d)
    assert np.all(np.isnan(field[unused]))
    np.testing.assert_allclose(field[where], ref, rtol=1e-9, atol=1e-12)
    assert field[dup] == field[where[7]]

    # picking the duplicate picks the vertex it was merged into
    model.state.set_pick_file_vertex(dup)
    assert model.state.picked == 7 and model.state.picked_file_vertex == where[7]
    with pytest.raises(
        ValueError, match=rf"vertex {unused[2]} \(counting from 0\) is used by no face"
    ):
        model.state.set_pick_file_vertex(unused[2])


def test_cli_vertex_and_csv_rows_are_the_files(files, tmp_path, monkeypatch, capsys):
    padded, compact, where, dup, unused = files
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    pick = int(where[40])
    csv, ref_csv = tmp_path / "d.csv", tmp_path / "ref.csv"
    args = ["--kind", "hks", "-k", str(K)]
    assert main(["distance", str(padded), "--vertex", str(pick), *args, "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert f"hks distance from vertex {pick}:" in out
    assert f"{len(unused)} empty (vertices no face uses)" in out
    assert main(["distance", str(compact), "--vertex", "40", *args, "--csv", str(ref_csv)]) == 0
    lines = csv.read_text().splitlines()
    assert lines[0] == "vertex,distance"
    rows = [line.split(",") for line in lines[1:]]
    assert [int(r[0]) for r in rows] == list(range(len(where) + len(unused) + 1))
    assert [int(r[0]) for r in rows if r[1] == ""] == unused
    values = np.array([float(r[1]) if r[1] else np.nan for r in rows])
    ref = np.loadtxt(ref_csv, delimiter=",", skiprows=1)[:, 1]
    np.testing.assert_allclose(values[where], ref, rtol=1e-9, atol=1e-12)
    assert values[dup] == values[where[7]] and values[pick] == 0.0

    assert main(["distance", str(padded), "--vertex", str(unused[0]), *args]) == 2
    err = capsys.readouterr().err
    assert f"--vertex {unused[0]}: vertex {unused[0]} (counting from 0) is used by no face" in err


def test_sessions_store_file_numbers_and_read_old_ones(files, tmp_path):
    padded, _, where, _, _ = files
    model = _model(tmp_path)
    pick = int(where[40])
    _distance(model, padded, pick)
    path = save_session(model.state, tmp_path / "s.json")
    data = json.loads(path.read_text())
    assert data["version"] == 2 and data["picked"] == pick
    assert data["mesh"]["file_vertices"] == model.state.mesh.n_file_vertices

    other = _model(tmp_path)
    restored = restore_session(other, path)
    for job in restored.jobs:
        other.jobs.wait(job)
    assert restored.notes == []
    assert other.state.picked == 40 and other.state.picked_file_vertex == pick
    np.testing.assert_array_equal(
        other.state.derived.distance_map(), model.state.derived.distance_map()
    )

    # a version-1 session stored the mesh's index
    data.update(version=1, picked=40)
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data))
    third = _model(tmp_path)
    restored = restore_session(third, old)
    for job in restored.jobs:
        third.jobs.wait(job)
    assert third.state.picked == 40 and third.state.picked_file_vertex == pick


def test_field_export_names_the_files_vertices(files, tmp_path):
    pv = pytest.importorskip("pyvista")
    from modalviewer.scene.export import save_field_mesh

    padded, _, where, _, _ = files
    model = _model(tmp_path)
    d = _distance(model, padded, int(where[40]))
    out = save_field_mesh(tmp_path / "f.vtp", model.state.mesh, {"hks distance": d})
    poly = pv.read(out)
    np.testing.assert_array_equal(poly.point_data["file_vertex"], where)
    np.testing.assert_allclose(poly.point_data["hks_distance"], d)


def test_field_export_to_ply_keeps_the_field_and_the_files_vertices(files, tmp_path):
    # VTK's PLY writer had dropped every point-data array: x, y, z and normals only
    import modalviewer as mv
    from modalviewer.scene.export import save_field_mesh

    padded, _, where, _, _ = files
    model = _model(tmp_path)
    d = _distance(model, padded, int(where[40]))
    mesh = model.state.mesh
    out = save_field_mesh(tmp_path / "f.ply", mesh, {"hks distance < 0.1": d})
    data = out.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0"
    props = [
        line.split()[1:] for line in header if line.startswith("property ") and "list" not in line
    ]
    assert props == [["double", "x"], ["double", "y"], ["double", "z"]] + [
        ["double", "hks_distance_0.1"],
        ["int", "file_vertex"],
    ]
    kinds = {"double": "<f8", "int": "<i4"}
    rows = np.frombuffer(data, [(n, kinds[t]) for t, n in props], mesh.n_vertices, end)
    np.testing.assert_array_equal(rows["hks_distance_0.1"], d)
    np.testing.assert_array_equal(rows["file_vertex"], where)
    np.testing.assert_array_equal(np.stack([rows["x"], rows["y"], rows["z"]], 1), mesh.vertices)
    back = mv.load_mesh(out)  # the mesh reads back, faces and all
    np.testing.assert_array_equal(back.faces, mesh.faces)


def test_cli_distance_to_a_second_mesh_in_file_numbers(files, tmp_path, monkeypatch, capsys):
    padded, compact, where, dup, unused = files
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    pick = int(where[40])
    csv = tmp_path / "ab.csv"
    argv = ["distance", str(compact), "--vertex", "40", "--to", str(padded), "--kind", "hks"]
    assert main([*argv, "-k", str(K), "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert f"best match {pick} (" in out and "mutual" in out and "not mutual" not in out
    rows = [line.split(",") for line in csv.read_text().splitlines()[1:]]
    assert len(rows) == len(where) + len(unused) + 1
    assert [int(r[0]) for r in rows if r[1] == ""] == unused
