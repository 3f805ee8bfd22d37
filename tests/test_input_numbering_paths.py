"""Issue 54: one vertex numbering, the input's, on every public path.  A mesh with unused
vertices at the start, in the middle and at the end and a duplicate that faces use comes
in through load_mesh and as_mesh (arrays, trimesh, pyvista, meshio); spectrum, signature,
distance from an input index, plot(vertex=), the command line's --vertex and CSV, the
viewer's pick and field export all name the same vertex and give one row per input
vertex."""

import csv

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import icosphere

K = 12


def _padded():
    base = icosphere(3)
    n, half = base.n_vertices, base.n_vertices // 2
    far = np.array([[5.0, 5.0, 5.0]])
    v = np.vstack([far, far + 1, base.vertices[:half], far + 2, base.vertices[half:]])
    v = np.vstack([v, base.vertices[[7]], far + 3])  # a duplicate of vertex 7, one unused
    where = np.concatenate([np.arange(half) + 2, np.arange(half, n) + 3])
    dup = len(v) - 2
    f = where[base.faces]
    faces_of_7 = np.flatnonzero((base.faces == 7).any(axis=1))[:2]
    f[faces_of_7] = np.where(f[faces_of_7] == where[7], dup, f[faces_of_7])
    unused = np.array([0, 1, half + 2, len(v) - 1])
    return base, v, f, where, dup, unused


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    base, v, f, where, dup, unused = _padded()
    obj = tmp_path_factory.mktemp("numbering") / "padded.obj"
    rows = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in v]
    rows += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    obj.write_text("\n".join(rows) + "\n# End of File\n")
    return base, v, f, where, dup, unused, obj


@pytest.fixture(autouse=True)
def _isolated(tmp_path, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("MODALVIEWER_SETTINGS", str(tmp_path / "settings.ini"))
    monkeypatch.setenv("MODALVIEWER_NO_DIALOGS", "1")


def _sources(v, f, obj):
    yield "load_mesh", lambda: mv.load_mesh(obj)
    yield "arrays", lambda: mv.as_mesh((v, f))
    trimesh = pytest.importorskip("trimesh")
    yield "trimesh", lambda: mv.as_mesh(trimesh.Trimesh(v, f, process=False))
    pv = pytest.importorskip("pyvista")
    cells = np.hstack([np.full((len(f), 1), 3), f]).ravel()
    yield "pyvista", lambda: mv.as_mesh(pv.PolyData(v, cells))
    meshio = pytest.importorskip("meshio")
    yield "meshio", lambda: mv.as_mesh(meshio.Mesh(v, [("triangle", f)]))


def test_every_way_in_keeps_the_input_numbering(case):
    base, v, f, where, dup, unused, obj = case
    clean = mv.compute_spectrum(base, "laplacian", k=K)
    expected = mv.multiscale_distance(clean, 40)
    for name, make in _sources(v, f, obj):
        mesh = make()
        np.testing.assert_array_equal(mesh.vertices, v, err_msg=name)
        np.testing.assert_array_equal(mesh.unused, unused, err_msg=name)
        assert mesh.merged_into[dup] == where[7], name
        spec = mv.compute_spectrum(mesh, "laplacian", k=K)
        assert spec.modes.shape == (len(v), K), name
        d = mv.multiscale_distance(spec, int(where[40]))
        np.testing.assert_allclose(d[where], expected, rtol=1e-9, atol=1e-14, err_msg=name)
        assert np.all(np.isnan(d[unused])), name
        assert d[dup] == pytest.approx(d[where[7]], rel=1e-9), name
        _, sig = mv.signature(spec, vertices=[int(where[40]), int(unused[2])])
        assert np.all(np.isfinite(sig[0])) and np.all(np.isnan(sig[1])), name


def test_the_report_counts_from_0_and_a_complete_obj_is_not_called_truncated(case):
    *_, dup, unused, obj = case
    text = str(mv.load_mesh(obj).report)
    assert "counting from 0" in text
    assert "truncated" not in text, text


def test_plot_picks_the_input_vertex(case):
    pytest.importorskip("pyvista")
    from modalviewer.plotting import _prepared_viewer

    base, v, f, where, dup, unused, obj = case
    mesh = mv.load_mesh(obj)
    spec = mv.compute_spectrum(mesh, "laplacian", k=K)
    pick = int(where[40])
    viewer = _prepared_viewer(mesh, spec, None, pick, "hks", K)
    try:
        assert viewer.picked == pick
        assert viewer.state.derived.field().legend.startswith(
            f"Heat kernel distance from vertex {pick}"
        )
        np.testing.assert_allclose(
            viewer.distance_map(), mv.multiscale_distance(spec, pick), rtol=1e-9, equal_nan=True
        )
    finally:
        viewer.close()
    with pytest.raises(ValueError, match=f"vertex {unused[2]} .*used by no face"):
        mv.plot(mesh, spec, vertex=int(unused[2]), size=(64, 48))
    picture = mv.plot(mesh, spec, vertex=pick, size=(64, 48))
    assert picture.shape == (48, 64, 3)
    # add_to_plotter: the same distance, drawn on the vertices faces use
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=[64, 48])
    scene = mv.add_to_plotter(plotter, mesh, spec, vertex=pick)
    np.testing.assert_allclose(
        scene.surface.point_data["field"], mv.multiscale_distance(spec, pick)[where], rtol=1e-12
    )
    plotter.close()


def test_the_command_line_vertex_and_csv(case, tmp_path, capsys):
    from modalviewer.cli import main

    base, v, f, where, dup, unused, obj = case
    pick = int(where[40])
    out = tmp_path / "d.csv"
    assert (
        main(
            [
                "distance",
                str(obj),
                "--vertex",
                str(pick),
                "--kind",
                "hks",
                "-k",
                str(K),
                "--csv",
                str(out),
            ]
        )
        == 0
    )
    with open(out, encoding="utf-8") as fh:
        rows = list(csv.reader(fh))[1:]
    assert len(rows) == len(v) and [int(r[0]) for r in rows] == list(range(len(v)))
    values = np.array([float(r[1]) if r[1] else np.nan for r in rows])
    spec = mv.compute_spectrum(mv.load_mesh(obj), "laplacian", k=K)
    np.testing.assert_allclose(
        values, mv.multiscale_distance(spec, pick), rtol=1e-8, equal_nan=True
    )
    assert values[pick] == 0.0
    printed = capsys.readouterr().out
    assert f"hks distance from vertex {pick}: max" in printed and "nan" not in printed
    assert (
        main(["distance", str(obj), "--vertex", str(int(unused[2])), "--kind", "hks", "-k", str(K)])
        == 2
    )
    assert f"vertex {unused[2]} (counting from 0) is used by no face" in capsys.readouterr().err


def test_the_viewer_picks_and_exports_in_the_input_numbering(case, tmp_path):
    pv = pytest.importorskip("pyvista")
    from modalviewer.viewer import Viewer

    base, v, f, where, dup, unused, obj = case
    pick = int(where[40])
    viewer = Viewer()
    try:
        mesh = viewer.open_mesh(obj)
        assert viewer.mesh is mesh and mesh.n_vertices == len(v)
        spec = viewer.compute("laplacian", k=K)
        assert spec.modes.shape == (len(v), K)
        viewer.state.set_display(distance_kind="hks")
        viewer.pick_vertex(pick)
        assert viewer.picked == pick
        assert f"from vertex {pick}" in viewer.state.derived.field().legend
        d = viewer.distance_map("hks")
        np.testing.assert_allclose(d, mv.multiscale_distance(spec, pick), rtol=1e-9, equal_nan=True)
        assert viewer.spectra["laplacian"].n_vertices == len(v)
        written = viewer.export_field(tmp_path / "field.vtp")
        poly = pv.read(written)
        assert poly.n_points == len(v)
        np.testing.assert_allclose(poly.points, v, rtol=0, atol=1e-6)
        (name,) = [n for n in poly.point_data.keys()]
        np.testing.assert_allclose(np.asarray(poly.point_data[name]), d, rtol=1e-9, equal_nan=True)
        with pytest.raises(ValueError, match=f"vertex {unused[0]} .*used by no face"):
            viewer.pick_vertex(int(unused[0]))
        # a field of the input's numbering (NaN where no face uses a vertex)
        height = np.where(np.isin(np.arange(len(v)), unused), np.nan, v[:, 2])
        viewer.show_field("height", height)
        name, values = viewer.current_field()
        np.testing.assert_allclose(values, height, equal_nan=True)
    finally:
        viewer.close()
