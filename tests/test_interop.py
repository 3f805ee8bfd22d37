"""Arrays in and out: as_mesh, load_mesh through meshio, operator_matrices, to_pyvista,
euclidean_modes, plot, add_to_plotter, view, and the library without Qt and pyvista."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import modalviewer as mv

ROOT = Path(__file__).resolve().parents[1]
ASSETS = ROOT / "assets"


@pytest.fixture(autouse=True)
def _isolated(tmp_path, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("MODALVIEWER_SETTINGS", str(tmp_path / "settings.ini"))
    monkeypatch.setenv("MODALVIEWER_NO_DIALOGS", "1")


@pytest.fixture(scope="module")
def plate():
    return mv.load_mesh(ASSETS / "demo_plate.obj")


@pytest.fixture(scope="module")
def spot():
    return mv.load_mesh(ASSETS / "spot.obj")


def _same(mesh, vertices, faces):
    np.testing.assert_allclose(mesh.vertices, vertices, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(mesh.faces, faces)


def test_arrays_round_trip_keeps_the_numbering(plate):
    v, f = np.array(plate.vertices), np.array(plate.faces)
    mesh = mv.as_mesh((v, f))
    _same(mesh, v, f)
    np.testing.assert_array_equal(mesh.file_vertices, np.arange(len(v)))
    assert mv.as_mesh(mesh) is mesh
    assert "arrays" in str(mesh.report)
    for path in (ASSETS / "demo_plate.obj", str(ASSETS / "demo_plate.obj")):  # a file
        _same(mv.as_mesh(path), plate.vertices, plate.faces)


def test_arrays_are_repaired_and_reported(plate):
    v = np.vstack([plate.vertices, [[9.0, 9.0, 9.0]]])  # a vertex no face uses
    mesh = mv.as_mesh((v, plate.faces), name="mine")
    assert mesh.n_vertices == len(v)  # vertex i of the arrays is vertex i of the mesh
    np.testing.assert_array_equal(mesh.unused, [plate.n_vertices])
    assert str(mesh.report).startswith("mine:")
    with pytest.raises(mv.MeshError, match="no faces"):
        mv.as_mesh((v, np.zeros((0, 3), int)))
    with pytest.raises(TypeError, match="as_mesh takes"):
        mv.as_mesh(42)


def test_trimesh_round_trip(plate):
    trimesh = pytest.importorskip("trimesh")
    tm = trimesh.Trimesh(plate.vertices, plate.faces, process=False)
    _same(mv.as_mesh(tm), plate.vertices, plate.faces)


def test_pyvista_round_trip_and_triangulation(plate):
    pv = pytest.importorskip("pyvista")
    poly = mv.to_pyvista(plate)
    _same(mv.as_mesh(poly), plate.vertices, plate.faces)
    quads = pv.Plane(i_resolution=3, j_resolution=2)  # 12 points, 6 quads
    mesh = mv.as_mesh(quads)
    assert mesh.n_faces == 12 and mesh.n_vertices == 12
    np.testing.assert_allclose(mesh.vertices, quads.points, atol=1e-12)
    assert "triangulated" in str(mesh.report)


def test_a_pyvista_grid_gives_its_surface_without_a_warning():
    """as_mesh of an UnstructuredGrid takes its outer surface as load_mesh of a .vtk grid
    does (pyvista 0.47+ warned of extract_surface's changing default there)."""
    import warnings

    pv = pytest.importorskip("pyvista")
    from modalviewer.core.primitives import icosphere

    sphere = icosphere(2)
    cells = np.hstack([np.full((sphere.n_faces, 1), 3), sphere.faces]).ravel()
    grid = pv.UnstructuredGrid(
        cells, np.full(sphere.n_faces, pv.CellType.TRIANGLE), sphere.vertices
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = mv.as_mesh(grid)
    assert mesh.n_faces == sphere.n_faces and "outer surface is used" in str(mesh.report)


def test_meshio_round_trip_and_files(plate, tmp_path):
    meshio = pytest.importorskip("meshio")
    m = meshio.Mesh(plate.vertices, [("triangle", plate.faces)])
    _same(mv.as_mesh(m), plate.vertices, plate.faces)
    for ext in (".vtu", ".msh"):
        path = tmp_path / f"plate{ext}"
        meshio.write(path, m) if ext == ".vtu" else meshio.write(path, m, file_format="gmsh22")
        loaded = mv.load_mesh(path)
        _same(loaded, plate.vertices, plate.faces)
        assert loaded.report.source == path.name
    quad = meshio.Mesh(
        np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]), [("quad", [[0, 1, 2, 3]])]
    )
    mesh = mv.as_mesh(quad)
    assert mesh.n_faces == 2 and "triangulated" in str(mesh.report)
    bad = tmp_path / "bad.vtu"
    bad.write_text("not a mesh")
    with pytest.raises(mv.MeshError, match="bad.vtu"):
        mv.load_mesh(bad)


@pytest.mark.parametrize("operator, k", [("laplacian", 12), ("shells", 14)])
def test_operator_matrices_give_the_spectrum_through_eigsh(plate, operator, k):
    spec = mv.compute_spectrum(plate, operator, k=k)
    K, M = mv.operator_matrices(plate, operator)
    assert sp.issparse(K) and sp.issparse(M) and M.format == "dia"
    np.testing.assert_allclose(M.diagonal()[:: 3 if spec.is_vector else 1], spec.mass)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()
    lam, _ = spla.eigsh(K, k, M, sigma=-1e-3 * spec.eigenvalues[-1])
    lam = np.sort(lam)
    nonzero = ~spec.zero_mode_mask()
    np.testing.assert_allclose(lam[nonzero], spec.eigenvalues[nonzero], rtol=1e-8)
    assert np.all(np.abs(lam[~nonzero]) < 1e-8 * spec.eigenvalues[-1])
    phi = spec.modes.reshape(-1, spec.k)  # M-orthonormal, as documented
    np.testing.assert_allclose(phi.T @ (M @ phi), np.eye(spec.k), atol=1e-8)
    unit = spec.euclidean_modes().reshape(-1, spec.k)
    np.testing.assert_allclose(np.linalg.norm(unit, axis=0), 1.0, rtol=1e-12)
    assert spec.euclidean_modes().shape == spec.modes.shape


def test_to_pyvista_arrays(plate):
    pytest.importorskip("pyvista")
    scalar = mv.compute_spectrum(plate, "laplacian", k=5)
    vector = mv.compute_spectrum(plate, "shells", k=8)
    z = plate.vertices[:, 2]
    poly = mv.to_pyvista(plate, scalar, fields={"z": z})
    assert poly.n_points == plate.n_vertices and poly.n_cells == plate.n_faces
    np.testing.assert_array_equal(poly.point_data["mode_3"], scalar.modes[:, 3])
    np.testing.assert_array_equal(poly.point_data["z"], z)
    np.testing.assert_array_equal(poly.field_data["eigenvalues"], scalar.eigenvalues)
    poly = mv.to_pyvista(plate, vector)
    assert poly.point_data["mode_7"].shape == (plate.n_vertices, 3)
    np.testing.assert_array_equal(poly.point_data["mode_7"], vector.modes[:, :, 7])
    with pytest.raises(ValueError, match="values"):
        mv.to_pyvista(plate, fields={"short": z[:-1]})


def _hues(img):
    rgb = img[..., :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    orange = (r > g + 40) & (g > b + 40)  # the modes' negative end, (0.96, 0.55, 0.12)
    blue = (b > r + 60) & (b > g + 30)  # their positive end, (0.16, 0.38, 0.78)
    return int(orange.sum()), int(blue.sum())


def test_plot_returns_the_viewers_picture(spot, tmp_path):
    pytest.importorskip("pyvista")
    spec = mv.compute_spectrum(spot, "laplacian", k=8)
    pic = mv.plot(spot, spec, mode=4, size=(320, 240), screenshot=tmp_path / "m.png")
    assert pic.array.shape == (240, 320, 3) and pic.array.dtype == np.uint8
    orange, blue = _hues(pic.array)
    assert orange > 200 and blue > 200
    assert (tmp_path / "m.png").stat().st_size > 1000
    assert pic._repr_png_().startswith(b"\x89PNG")
    field = mv.plot(spot, field={"height": spot.vertices[:, 1]}, size=(320, 240))
    red = (field.array[..., 0].astype(int) > field.array[..., 2].astype(int) + 60).sum()
    assert red > 200  # white to red
    dist = mv.plot(spot, spec, vertex=0, size=(320, 240), k=8)
    assert not np.array_equal(dist.array, field.array)
    wave = mv.plot(spot, spec, vertex=0, kind="wks", size=(320, 240), k=8)
    assert not np.array_equal(wave.array, dist.array)  # the wave kernel's own map
    # a mode without a spectrum is refused (it drew the plain grey mesh without a word)
    with pytest.raises(ValueError, match="mode=8 is a mode of a spectrum: pass one"):
        mv.plot(spot, mode=8)


def test_add_to_plotter(spot):
    pv = pytest.importorskip("pyvista")
    spec = mv.compute_spectrum(spot, "laplacian", k=6)
    plotter = pv.Plotter(off_screen=True, window_size=[320, 240])
    scene = mv.add_to_plotter(plotter, spot, spec, mode=3)
    np.testing.assert_allclose(scene.surface.point_data["field"], spec.modes[:, 3])
    orange, blue = _hues(plotter.screenshot())
    assert orange > 50 and blue > 50  # both ends of the diverging colours, seen from +z
    plotter.close()


def test_view_without_blocking_returns_the_window(spot):
    pytest.importorskip("PySide6")
    spec = mv.compute_spectrum(spot, "laplacian", k=6)
    fields = {"x": spot.vertices[:, 0], "y": spot.vertices[:, 1]}
    window = mv.view(spot, spectrum=spec, fields=fields, block=False)
    try:
        assert window.viewer.mesh is not None
        assert window.viewer.mesh.n_vertices == spot.n_vertices
        assert window.viewer.state.spectrum("laplacian") is spec
        # the window's surface shows the first field, and the others are the viewer's
        np.testing.assert_allclose(window.scene.surface.point_data["field"], fields["x"])
        window.viewer.show_field("y")
        np.testing.assert_allclose(window.scene.surface.point_data["field"], fields["y"])
        assert window.status_line.text().startswith("y: blue +, white 0, orange -")
    finally:
        window.close()


def test_the_library_works_without_qt_and_pyvista():
    code = """
import sys
for name in ("PySide6", "pyvista", "vtk", "vtkmodules", "qtpy", "pyvistaqt", "pymeshlab"):
    sys.modules[name] = None
import modalviewer as mv
mesh = mv.load_mesh(mv.asset_path("demo_plate.obj"))
spec = mv.compute_spectrum(mesh, "modified_dirichlet", k=5)
mesh2 = mv.as_mesh((mesh.vertices, mesh.faces))
K, M = mv.operator_matrices(mesh2, "laplacian")
assert spec.k == 5 and K.shape == M.shape
print("ok")
"""
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().endswith("ok")


def test_an_interactive_plot_is_the_same_scene_as_a_page(spot, tmp_path):
    """plot(interactive=True): the viewer's scene exported as a standalone vtk.js page,
    shown by Jupyter in an iframe; the page holds the surface's points and the mode's
    values, and the legend is written above it."""
    import base64
    import json
    import re
    import zipfile
    from io import BytesIO

    spec = mv.compute_spectrum(spot, "laplacian", k=8)
    page = mv.plot(spot, spec, mode=3, interactive=True, size=(500, 400))
    assert isinstance(page, mv.InteractivePicture)
    html = page._repr_html_()
    assert "<iframe" in html and 'width="500"' in html and "mode 3" in html
    out = page.save(tmp_path / "mode3")
    assert out.suffix == ".html" and out.stat().st_size > 100_000
    # the exported scene: a base64 zip whose index holds vtk.js arrays (base64 of their
    # bytes); the surface's points and the mode's values are among them
    arrays = []
    for blob in re.findall(r"[A-Za-z0-9+/=]{10000,}", page.html):
        try:
            with zipfile.ZipFile(BytesIO(base64.b64decode(blob))) as z:
                index = json.loads(z.read("index.json"))
        except (zipfile.BadZipFile, ValueError, KeyError):
            continue
        for entry in index.get("hashes", {}).values():
            if entry.get("type") == "Float64Array":
                arrays.append(np.frombuffer(base64.b64decode(entry["content"]), np.float64))
            elif entry.get("type") == "Float32Array":
                arrays.append(np.frombuffer(base64.b64decode(entry["content"]), np.float32))
    n = spot.n_vertices
    points = [a for a in arrays if a.size == 3 * n]
    assert any(np.allclose(a.reshape(n, 3), spot.vertices) for a in points)
    values = [a for a in arrays if a.size == n]
    assert any(np.allclose(a, spec.mode(3), atol=1e-6) for a in values)


def test_an_interactive_plot_without_the_extra_is_an_image_with_a_warning(spot, monkeypatch):
    from modalviewer import plotting

    monkeypatch.setattr(plotting, "interactive_available", lambda: False)
    with pytest.warns(UserWarning, match=r"modalviewer\[notebook\]"):
        picture = mv.plot(spot, field=spot.vertices[:, 1], interactive=True, size=(200, 150))
    assert isinstance(picture, mv.Picture) and picture.shape[:2] == (150, 200)


@pytest.mark.parametrize(
    "operator, word", [("laplacian", "Heat kernel"), ("modified_dirichlet", "Feature")]
)
def test_plot_draws_the_distance_of_the_spectrum_it_is_given(spot, operator, word, monkeypatch):
    pytest.importorskip("pyvista")
    from modalviewer.plotting import _prepared_viewer, distance_kind_of
    from modalviewer.viewer import Viewer

    spec = mv.compute_spectrum(spot, operator, k=8)

    def no_compute(*args, **kwargs):
        raise AssertionError("plot computed a spectrum it was not asked for")

    with monkeypatch.context() as m:
        m.setattr(Viewer, "compute", no_compute)
        picture = mv.plot(spot, spec, vertex=7, size=(160, 120))
    assert picture.shape == (120, 160, 3)
    viewer = _prepared_viewer(spot, spec, None, 7, distance_kind_of(spec, None), 8)
    try:
        legend = viewer.state.derived.field().legend
        assert legend.startswith(f"{word} distance from vertex 7"), legend
        assert viewer.state.spectrum("shells") is None  # no 3D shells computed
        np.testing.assert_allclose(
            viewer.state.derived.field().values, mv.multiscale_distance(spec, 7), atol=1e-12
        )
    finally:
        viewer.close()
    shells_normal = mv.compute_spectrum(spot, "shells_normal", k=8)
    with pytest.raises(ValueError, match="defines no distance; pass kind="):
        distance_kind_of(shells_normal, None)
    assert distance_kind_of(None, None) == "vibration"
    assert distance_kind_of(spec, "vibration") == "vibration"


def test_a_missing_extra_is_named_in_one_line(tmp_path):
    (tmp_path / "x.vtp").write_bytes(b"<VTKFile></VTKFile>")
    code = f"""
import sys
for name in ("PySide6", "pyvista", "vtk", "vtkmodules", "qtpy", "pyvistaqt"):
    sys.modules[name] = None
import numpy as np
import modalviewer as mv
mesh = mv.load_mesh(mv.asset_path("demo_plate.obj"))
spec = mv.compute_spectrum(mesh, "laplacian", k=5)
calls = {{
    "plot": lambda: mv.plot(mesh, spec),
    "to_pyvista": lambda: mv.to_pyvista(mesh),
    "add_to_plotter": lambda: mv.add_to_plotter(None, mesh, spec),
    "view": lambda: mv.view(mesh, block=False),
    "image": lambda: mv.Viewer().image(),
    "screenshot": lambda: mv.Viewer().export_screenshot({str(tmp_path / "s.png")!r}),
    "vtp": lambda: mv.load_mesh({str(tmp_path / "x.vtp")!r}),
}}
for name, call in calls.items():
    try:
        call()
    except Exception as exc:
        print(name, type(exc).__name__, isinstance(exc, ModuleNotFoundError), str(exc))
    else:
        print(name, "no error")
"""
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert len(lines) == 7, out.stdout
    for line in lines:
        name, kind, is_missing, message = line.split(" ", 3)
        assert kind == "MissingExtraError" and is_missing == "True", line
        assert message.endswith('which is not installed: pip install "modalviewer[viewer]"'), line
        assert "damaged" not in message, line
    assert lines[-1].startswith("vtp MissingExtraError True reading .vtp files needs pyvista")


def test_every_sparse_result_is_one_kind_and_products_agree(plate):
    n = plate.n_vertices
    results = {
        "stiffness_matrix": mv.stiffness_matrix(plate),
        "mass_matrix": mv.mass_matrix(plate),
        "modified_dirichlet_matrix": mv.modified_dirichlet_matrix(plate),
        "shells_hessian": mv.shells_hessian(plate),
        "normal_shells_hessian": mv.normal_shells_hessian(plate),
    }
    for operator in ("laplacian", "shells"):
        K, M = mv.operator_matrices(plate, operator)
        results[f"{operator} K"], results[f"{operator} M"] = K, M
    for name, A in results.items():
        assert isinstance(A, sp.spmatrix), (name, type(A))
        x = np.ones(A.shape[1])
        assert (A @ x).shape == (A * x).shape == (A.shape[0],), name
    K, M = mv.operator_matrices(plate, "laplacian")
    x = np.arange(n, dtype=float)
    np.testing.assert_allclose(M * x, M.diagonal() * x, rtol=1e-15)
