"""Loading, repair reports, clear refusals, spectrum files."""

import subprocess
import sys

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import grid_plate, icosphere


def _write_obj(path, v, f):
    with open(path, "w") as fh:
        for p in v:
            fh.write(f"v {float(p[0])} {float(p[1])} {float(p[2])}\n")
        for t in f:
            fh.write("f " + " ".join(str(i + 1) for i in t) + "\n")
    return path


@pytest.mark.parametrize("ext", [".obj", ".ply", ".stl", ".off", ".vtp", ".vtk"])
def test_formats_round_trip(tmp_path, ext):
    mesh = icosphere(2)
    path = tmp_path / f"sphere{ext}"
    if ext in (".vtp", ".vtk"):
        import pyvista as pv

        faces = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
        pv.PolyData(mesh.vertices, faces).save(path)
    else:
        import trimesh

        trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).export(path)
    loaded = mv.load_mesh(path)
    assert loaded.n_vertices == mesh.n_vertices and loaded.n_faces == mesh.n_faces
    assert loaded.total_area == pytest.approx(mesh.total_area, rel=1e-6)


@pytest.mark.parametrize(
    ("ext", "fast_path"),
    [(".off", "_ascii_fast"), (".ply", "_ascii_fast"), (".obj", "_read_obj_fast")],
)
def test_the_fast_readers_read_what_the_record_readers_read(tmp_path, monkeypatch, ext, fast_path):
    """Well-formed text files go through numpy in one go; the arrays are those of the
    record-by-record reader (which reads and checks every other file) to the bit."""
    import trimesh

    from modalviewer import readers

    rng = np.random.default_rng(3)
    mesh = icosphere(2)
    vertices = mesh.vertices + rng.normal(scale=1e-3, size=mesh.vertices.shape)
    path = tmp_path / f"sphere{ext}"
    tm = trimesh.Trimesh(vertices, mesh.faces, process=False)
    if ext == ".ply":
        path.write_bytes(trimesh.exchange.ply.export_ply(tm, encoding="ascii"))
    else:
        tm.export(path)
    fast = readers.read_mesh_file(path)
    monkeypatch.setattr(readers, fast_path, lambda *args: None)
    slow = readers.read_mesh_file(path)
    assert fast.vertices.shape == (mesh.n_vertices, 3) and fast.faces.shape == (mesh.n_faces, 3)
    np.testing.assert_array_equal(fast.vertices, slow.vertices)
    np.testing.assert_array_equal(fast.faces, slow.faces)
    assert fast.notes == slow.notes


def test_stl_vertices_are_the_distinct_corners_in_the_order_they_first_appear():
    from modalviewer.readers import _stl_vertices

    rng = np.random.default_rng(5)
    corners = rng.integers(0, 6, size=(3000, 3)).astype(np.float64) / 4
    corners[7], corners[8] = [-0.0, 0.0, 0.0], [0.0, 0.0, 0.0]  # one position
    corners[9], corners[10] = [1.0 + 1e-12, 0.0, 0.0], [1.0, 0.0, 0.0]  # two
    vertices, triangles = _stl_vertices(corners)
    _, first, inverse = np.unique(corners, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    np.testing.assert_array_equal(vertices, corners[first[order]])
    np.testing.assert_array_equal(vertices[triangles.ravel()], corners)
    assert len(vertices) == len(first) and (np.diff(first[order]) > 0).all()


def test_an_unstructured_grid_file_reads_without_a_warning(tmp_path):
    # pyvista's extract_surface warned (FutureWarning) for every .vtk grid read, also in
    # batch output
    import warnings

    import pyvista as pv

    mesh = icosphere(2)
    cells = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
    grid = pv.UnstructuredGrid(cells, np.full(mesh.n_faces, pv.CellType.TRIANGLE), mesh.vertices)
    path = tmp_path / "grid.vtk"
    grid.save(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loaded = mv.load_mesh(path)
    assert loaded.n_faces == mesh.n_faces


def test_repairs_are_made_and_reported(tmp_path):
    plate = grid_plate(4, 4)
    n = plate.n_vertices
    v = np.vstack([plate.vertices, plate.vertices[:3], [[9.0, 9.0, 9.0]]])  # dups + stray
    f = plate.faces.copy()
    f[0] = f[0][::-1]  # inconsistent orientation
    extra = np.array([[0, 1, 2], [n, n + 1, n + 2]])  # collinear (zero area), via duplicates
    mesh = mv.repair_mesh(v, np.vstack([f, extra]), source="messy")
    text = str(mesh.report)
    assert "Merged 3 duplicate vertices" in text
    assert "1 vertex used by no face" in text
    assert "degenerate" in text and "Flipped 1 face" in text
    assert mesh.n_faces == plate.n_faces and mesh.solver_mesh.n_vertices == plate.n_vertices
    assert mesh.n_vertices == len(v)  # the input's numbering
    assert mesh.is_consistently_oriented
    np.testing.assert_array_equal(mesh.solver_mesh.vertices, plate.vertices)


def test_duplicate_vertices_merged(tmp_path):
    # two triangles that share an edge only by coordinates
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    path = _write_obj(tmp_path / "split.obj", v, [[0, 1, 2], [3, 4, 5]])
    mesh = mv.load_mesh(path)
    assert mesh.n_vertices == 6 and mesh.solver_mesh.n_vertices == 4
    assert "Merged 2 duplicate vertices" in str(mesh.report)
    assert list(mesh.merged_into) == [0, 1, 2, 1, 4, 2]
    raw = mv.load_mesh(path, repair=False)
    assert raw.n_vertices == 6


def test_quads_are_triangulated(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    mesh = mv.load_mesh(path)
    assert mesh.n_faces == 2 and mesh.total_area == pytest.approx(1.0)


@pytest.mark.parametrize(
    "content,fragment",
    [
        ("", "empty"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
        ("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "NaN"),
    ],
)
def test_clear_errors(tmp_path, content, fragment):
    path = tmp_path / "bad.obj"
    path.write_text(content)
    with pytest.raises(mv.MeshError, match=fragment):
        mv.load_mesh(path)


def test_direct_construction_errors():
    with pytest.raises(mv.MeshError, match="has 3 vertices"):
        mv.Mesh(np.eye(3), [[0, 1, 3]])
    with pytest.raises(mv.MeshError, match="no faces"):
        mv.Mesh(np.eye(3), np.zeros((0, 3)))
    with pytest.raises(mv.MeshError, match="NaN"):
        mv.Mesh([[0, 0, 0], [1, 0, 0], [0, np.inf, 0]], [[0, 1, 2]])
    with pytest.raises(mv.MeshError, match="zero area"):
        mv.Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]])
    assert issubclass(mv.MeshError, ValueError)
    with pytest.raises(mv.MeshError, match="unsupported"):
        mv.load_mesh("mesh.xyz")


def test_non_manifold_mesh_refuses_shells_but_not_laplacian():
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]]
    f = [[0, 1, 2], [1, 0, 3], [0, 1, 4]]  # edge 0-1 shared by three faces
    mesh = mv.Mesh(v, f)
    assert not mesh.is_edge_manifold
    for operator in ("shells", "shells_normal", "modified_dirichlet"):
        with pytest.raises(mv.MeshError, match="non-manifold"):
            mv.compute_spectrum(mesh, operator, k=3)
    spec = mv.compute_spectrum(mesh, "laplacian", k=3)
    assert np.all(np.isfinite(spec.eigenvalues))


def test_spectrum_file_round_trip_and_hash(tmp_path, spot):
    spec = mv.compute_spectrum(spot, "shells", k=10)
    path = tmp_path / "s.npz"
    mv.save_spectrum(spec, path)
    back = mv.load_spectrum(path, mesh_hash=spot.hash)
    assert back.operator == "shells" and back.modes.shape == spec.modes.shape
    np.testing.assert_array_equal(back.eigenvalues, spec.eigenvalues)
    assert back.parameters["bending"] == 1.0
    # the solver's stage clock travels with the spectrum (`modalviewer compute` prints it)
    stages = back.parameters["seconds_by_stage"]
    assert stages == spec.parameters["seconds_by_stage"] and stages["solves"] > 0
    assert sum(stages.values()) <= back.parameters["seconds_total"] + 1e-3
    assert back.parameters["operator_columns"] >= 10
    with pytest.raises(mv.SpectrumFileError, match="another mesh"):
        mv.load_spectrum(path, mesh_hash="0" * 64)
    damaged = tmp_path / "damaged.npz"
    damaged.write_bytes(path.read_bytes()[:200])
    with pytest.raises(mv.SpectrumFileError):
        mv.load_spectrum(damaged)
    assert not list(tmp_path.glob("*.part"))


def test_import_loads_no_qt_and_no_vtk():
    code = (
        "import sys, modalviewer as mv; mv.load_mesh; "
        "bad = [m for m in sys.modules if m.split('.')[0] in "
        "('qtpy', 'PySide6', 'PyQt5', 'PyQt6', 'vtk', 'vtkmodules', 'pyvista', 'pyvistaqt')]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("text", ["garbage\nmore garbage\n", "# only a comment\n"])
def test_an_obj_without_vertices_names_the_file_and_the_format(tmp_path, text):
    path = tmp_path / "broken.obj"
    path.write_text(text)
    with pytest.raises(mv.MeshError, match=r"^broken\.obj: no vertices found in this OBJ file"):
        mv.load_mesh(path)


def test_a_mesh_loaded_without_repair_says_what_was_not_checked(tmp_path):
    # its report said "no problems found" for a triangle soup of 5856 components
    import modalviewer as mv

    spot = mv.load_mesh(mv.asset_path("spot.obj"))
    soup_v = spot.vertices[spot.faces[:50]].reshape(-1, 3)
    soup_f = np.arange(150).reshape(-1, 3)
    mesh = mv.as_mesh((soup_v, soup_f), repair=False)
    text = str(mesh.report)
    assert "no problems found" not in text
    assert "150 vertices, 50 faces, 50 components" in text
    assert "Not repaired (repair=False)" in text
