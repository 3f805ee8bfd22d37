"""The real window, rendering off-screen: pixels, clicks, animation, export, cancel."""

import numpy as np
import pytest
from PIL import Image
from qtpy import QtCore

from modalviewer.core.primitives import icosphere
from modalviewer.gui.viewport import grab_views

pytestmark = pytest.mark.gui


def _classify(img):
    r, g, b = (img[:, :, i].astype(int) for i in range(3))
    blue = (b > r + 60) & (b > g + 20)
    orange = (r > b + 80) & (g > b + 20) & (r > g + 20)
    white = (r > 240) & (g > 240) & (b > 240)
    black = (r < 50) & (g < 50) & (b < 50)
    red = (r > g + 80) & (r > b + 80)
    return {
        "blue": blue.sum(),
        "orange": orange.sum(),
        "white": white.sum(),
        "black": black.sum(),
        "red": red.sum(),
    }


def _both_sides(window):
    """Colour counts summed over the front view and the view from behind."""
    total = _classify(window.viewport.render_now())
    window.plotter.camera.Azimuth(180)
    back = _classify(window.viewport.render_now())
    window.plotter.camera.Azimuth(180)
    return {key: total[key] + back[key] for key in total}


def test_mode_colours_and_isolines(window, spot_path):
    assert window.open_mesh(spot_path)
    window.state.style.colorbar = False  # the legend's black text would count as lines
    spec = window.compute("laplacian", k=20, wait=True)
    assert spec.k == 20 and window.state.current_operator() == "laplacian"
    window.show_mode(6)
    counts = _both_sides(window)
    assert counts["blue"] > 2000, counts
    assert counts["orange"] > 2000, counts
    assert counts["black"] > 200, counts  # isolines
    assert window.scene.iso_actor.GetVisibility() and window.scene.isolines.n_points > 100
    # symmetric range: white at zero
    lo, hi = window.scene.clim
    assert lo == pytest.approx(-hi)
    window.modes_panel.iso_spin.setValue(0)
    no_lines = _both_sides(window)
    assert no_lines["black"] < counts["black"] / 3
    assert "lambda_6" in window.modes_panel.eigen_label.text()


def test_a_freshly_opened_mesh_is_plain_grey(window, spot_path):
    assert window.open_mesh(spot_path)
    img = window.viewport.render_now().astype(int)
    r, g, b = img[:, :, 0], img[:, :, 1], img[:, :, 2]
    surface = (r < 235) | (g < 235) | (b < 235)  # not the white background
    assert surface.sum() > 5000
    # shaded grey: the channels agree (the default colour map's dark purple did not)
    spread = np.max([r, g, b], axis=0) - np.min([r, g, b], axis=0)
    assert np.median(spread[surface]) < 12, np.median(spread[surface])
    assert np.median(g[surface]) > 90


def test_every_dock_fits_its_contents_without_sideways_scrolling(window, spot_path):
    from qtpy import QtWidgets

    window.open_mesh(spot_path)
    window.show()
    QtWidgets.QApplication.processEvents()
    for dock in window.findChildren(QtWidgets.QDockWidget):
        scroll = dock.widget()
        inner = scroll.widget()
        assert inner.minimumSizeHint().width() <= scroll.viewport().width(), dock.windowTitle()


def test_animation_moves_the_surface(window, spot_path, qtbot):
    window.open_mesh(spot_path)
    window.compute("shells", k=12, wait=True)
    window.show_mode(8)
    window.state.style.shell_coloring = "normal"  # a still picture on the rest shape
    rest = np.array(window.scene.surface.points)
    before = window.viewport.render_now()
    window.animation_panel.play_button.click()
    # frames arrive every 16 ms on an idle machine; allow for a loaded one
    qtbot.waitUntil(lambda: len(window.scene_view.frame_times) > 3, timeout=5000)
    assert window.scene_view.timer.isActive()
    moved = np.array(window.scene.surface.points)
    assert np.abs(moved - rest).max() > 1e-3 * window.mesh.bounding_box_diagonal
    window.animation_frame(np.pi / 2)  # peak displacement
    after = window.viewport.render_now()
    assert np.mean(np.any(before != after, axis=2)) > 0.002
    window.animation_panel.play_button.click()
    assert not window.scene_view.timer.isActive()
    np.testing.assert_allclose(window.scene.surface.points, rest)
    # the deformed shape: still at the amplitude, the animation swings about the rest
    window.state.style.shell_coloring = "deformed"
    peak = np.linalg.norm(window.scene.surface.points - rest, axis=1).max()
    assert peak == pytest.approx(0.1 * window.mesh.bounding_box_diagonal, rel=1e-6)
    window.animation_panel.play_button.click()
    window.animation_frame(0.0)
    np.testing.assert_allclose(window.scene.surface.points, rest)
    window.animation_panel.play_button.click()
    peak = np.linalg.norm(window.scene.surface.points - rest, axis=1).max()
    assert peak == pytest.approx(0.1 * window.mesh.bounding_box_diagonal, rel=1e-6)


def test_click_picks_the_vertex_under_the_mouse(window, spot_path, qtbot, display_position):
    window.open_mesh(spot_path)
    window.compute("laplacian", k=20, wait=True)
    widget = window.viewport.widget
    h = widget.height()
    window.viewport.render_now()
    target = window.scene.vertex_at_display(widget.width() / 2, h / 2)
    assert target is not None
    x, y, _ = display_position(window.scene, target)
    qtbot.mouseClick(
        widget,
        QtCore.Qt.MouseButton.LeftButton,
        pos=QtCore.QPoint(int(round(x)), int(round(h - 1 - y))),
    )
    assert window.picked == target
    # the vibration distance needs the shells spectrum: computed in the worker
    qtbot.waitUntil(lambda: window.state.display.kind == "distance", timeout=120000)
    d = window.distance_map()
    assert d.shape == (window.mesh.n_vertices,) and d[target] == 0.0 and d.max() > 0
    img = window.viewport.render_now()
    assert _classify(img)["red"] > 500


def test_threshold_display_and_slider(window, spot_path):
    window.open_mesh(spot_path)
    window.compute("modified_dirichlet", k=30, wait=True)
    window.pick_vertex(100)
    d = window.show_distance("feature", display="threshold", share=0.1)
    assert d is not None
    low = _classify(window.viewport.render_now())["blue"]
    window.distances_panel.by_share_check.setChecked(False)  # linear in the largest
    window.distances_panel.threshold_slider.setValue(700)  # what dragging the slider does
    assert window.state.display.threshold == pytest.approx(0.7)
    high = _classify(window.viewport.render_now())["blue"]
    assert high > low + 1000
    field = window.scene.surface.point_data["field"]
    np.testing.assert_array_equal(field, d)  # blue up to the threshold, by the colour table


def test_export_png_size_and_transparency(window, spot_path, tmp_path):
    window.open_mesh(spot_path)
    w, h = window.viewport.widget.width(), window.viewport.widget.height()
    out = window.export_screenshot(tmp_path / "fig.png", scale=2, transparent=True)
    img = Image.open(out)
    assert img.size == (2 * w, 2 * h) and img.mode == "RGBA"
    alpha = np.array(img)[:, :, 3]
    assert alpha[0, 0] == 0 and alpha[h, w] == 255
    out2 = window.export_screenshot(tmp_path / "plain.png")
    assert Image.open(out2).size == (w, h)
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def _big_mesh_file(tmp_path):
    import trimesh

    sphere = icosphere(6)  # 40962 vertices
    path = tmp_path / "big.ply"
    trimesh.Trimesh(sphere.vertices, sphere.faces, process=False).export(path)
    return path


def test_cancel_a_running_computation(window, tmp_path, qtbot):
    window.open_mesh(_big_mesh_file(tmp_path))
    window.compute("shells", k=200, wait=False)
    job = window.running_job
    assert job is not None and window.status_widgets.progress.cancel_button.isVisible()
    qtbot.wait(1500)
    window.status_widgets.progress.cancel_button.click()
    qtbot.waitUntil(lambda: job.done, timeout=30000)
    assert job.status == "cancelled" and not window.busy
    assert "shells" not in window.spectra
    assert not window.status_widgets.progress.cancel_button.isVisible()


def test_loading_a_mesh_during_a_computation_drops_the_old_result(
    window, tmp_path, spot_path, qtbot
):
    window.open_mesh(_big_mesh_file(tmp_path))
    window.compute("laplacian", k=50, wait=False)
    old_job = window.running_job
    assert window.open_mesh(spot_path)
    assert window.mesh.n_vertices == 2930
    qtbot.waitUntil(lambda: old_job.done, timeout=60000)
    qtbot.wait(100)
    assert window.spectra == {}
    # the jobs panel's "Last:" does not describe the old mesh's cancelled job
    assert window.jobs_panel.last.isHidden(), window.jobs_panel.last.text()
    spec = window.compute("laplacian", k=10, wait=True)
    assert spec.n_vertices == 2930
    qtbot.wait(100)
    assert "Last:" in window.jobs_panel.last.text() and not window.jobs_panel.last.isHidden()
    # and is cleared when another mesh is opened
    assert window.open_mesh(spot_path.with_name("demo_hand.obj"))
    assert window.jobs_panel.last.isHidden() and window.jobs_panel.last.text() == ""


def _slow_reading(monkeypatch, seconds: float):
    """load_mesh taking ``seconds`` longer, as a big file's reading does."""
    import time

    from modalviewer import io

    real = io.load_mesh

    def slow(path, strict=True):
        time.sleep(seconds)
        return real(path, strict=strict)

    monkeypatch.setattr(io, "load_mesh", slow)


def test_a_mesh_file_is_read_while_the_window_keeps_drawing(window, spot_path, monkeypatch):
    """A mesh file is read in a worker thread: while a reading of 1.5 s goes on, the
    window's event loop runs (a 20 ms timer ticks), the dialog naming the file shows,
    and then the mesh opens.  Before, the window froze for the whole reading (a
    1.5M-vertex OBJ: 15 to 20 s with the file dialog painted over it)."""
    from qtpy import QtCore, QtWidgets

    _slow_reading(monkeypatch, 1.5)
    ticks, seen = [], []
    timer = QtCore.QTimer()
    timer.timeout.connect(lambda: ticks.append(1))
    timer.start(20)

    def look():
        seen.extend(
            d.labelText() for d in window.findChildren(QtWidgets.QProgressDialog) if d.isVisible()
        )

    QtCore.QTimer.singleShot(1200, look)
    assert window.open_mesh(spot_path)
    timer.stop()
    assert len(ticks) >= 30, len(ticks)  # 1.5 s of 20 ms ticks: 75 when idle
    assert seen and seen[0].startswith("Opening spot.obj"), seen
    assert window.state.mesh is not None and window.state.mesh_path == spot_path


def test_a_slow_reading_can_be_cancelled_and_keeps_the_mesh(window, spot_path, monkeypatch):
    from qtpy import QtCore, QtWidgets

    window.open_mesh(spot_path)
    shown = window.state.mesh
    _slow_reading(monkeypatch, 2.0)

    def cancel():  # the dialog's Cancel button, as a person presses it
        for dialog in window.findChildren(QtWidgets.QProgressDialog):
            if dialog.isVisible():
                dialog.findChild(QtWidgets.QPushButton).click()

    QtCore.QTimer.singleShot(1200, cancel)
    assert not window.open_mesh(spot_path.with_name("demo_hand.obj"))
    assert window.state.mesh is shown
    assert "cancelled" in window.statusBar().currentMessage()


def test_keys_pressed_while_a_mesh_opens_are_all_dropped(window, spot_path, monkeypatch):
    """While a file is read, every keyed action and shortcut of the window is disabled
    (a key then does nothing, now or after loading) and gets its state back after: Ctrl+R
    starts no computation, C shows no curvature on the old or the new mesh."""
    from qtpy import QtCore, QtGui

    window.open_mesh(spot_path)
    keyed = {
        a.shortcut().toString(): a
        for a in window.findChildren(QtGui.QAction)
        if not a.shortcut().isEmpty()
    }
    before = {key: a.isEnabled() for key, a in keyed.items()}
    assert before["Ctrl+R"] and before["C"] and before["M"]
    _slow_reading(monkeypatch, 1.0)
    during, ran = {}, []
    monkeypatch.setattr(window.viewer, "compute", lambda *a, **kw: ran.append("compute"))
    monkeypatch.setattr(window.viewer, "show_curvature", lambda: ran.append("curvature"))

    def press():  # what the keys' shortcuts would run, as a person presses them
        during.update({key: a.isEnabled() for key, a in keyed.items()})
        for key in ("Ctrl+R", "C", "M", "R"):
            keyed[key].trigger()

    QtCore.QTimer.singleShot(500, press)
    assert window.open_mesh(spot_path.with_name("demo_hand.obj"))
    assert during and not any(during.values()), during
    assert {key: a.isEnabled() for key, a in keyed.items()} == before
    assert ran == []
    window.show_curvature()  # the same slot with the keys back on: it runs
    assert ran == ["curvature"]


def test_bad_file_gives_a_message_and_keeps_the_mesh(window, spot_path, tmp_path):
    window.open_mesh(spot_path)
    bad = tmp_path / "broken.obj"
    bad.write_text("")
    assert not window.open_mesh(bad)
    assert "empty" in window.last_error
    assert window.mesh.n_vertices == 2930
    junk = tmp_path / "junk.ply"
    junk.write_bytes(np.random.default_rng(0).bytes(3000))
    assert not window.open_mesh(junk)
    assert "junk.ply" in window.last_error


def test_settings_are_remembered(qtbot, spot_path):
    from modalviewer.gui import MainWindow, window_settings

    first = MainWindow(remember_settings=True)
    qtbot.addWidget(first)
    first.modes_panel.iso_spin.setValue(21)
    first.open_mesh(spot_path)
    first.close()
    second = MainWindow(remember_settings=True)
    qtbot.addWidget(second)
    assert second.modes_panel.iso_spin.value() == 21 and second.state.style.isolines == 21
    assert str(spot_path.resolve()) in window_settings.recent_files(second)
    second.close()


def test_cached_spectrum_reopens_instantly(window, spot_path):
    window.open_mesh(spot_path)
    first = window.compute("shells_normal", k=15, wait=True)
    window.open_mesh(spot_path)
    again = window.compute("shells_normal", k=15, wait=True)
    assert not window.busy  # served from the disk cache
    np.testing.assert_array_equal(first.eigenvalues, again.eigenvalues)


def test_linked_comparison_of_three_operators(window, spot_path, tmp_path, qtbot):
    window.open_mesh(spot_path)
    for op in ("laplacian", "modified_dirichlet", "shells_normal"):
        window.compute(op, k=12, wait=True)
    compare = window.open_comparison(["laplacian", "modified_dirichlet", "shells_normal"])
    cameras = {id(vp.plotter.renderer.GetActiveCamera()) for vp in compare.viewports}
    assert len(cameras) == 1  # one shared camera
    compare.comparison.show_mode(7)
    for op, scene in zip(compare.comparison.items, compare.scenes, strict=True):
        np.testing.assert_allclose(
            scene.surface.point_data["field"], window.spectra[op].mode(7), rtol=0, atol=0
        )
    images = grab_views(compare.viewports, compare.scenes)
    compare.viewports[0].plotter.camera.Azimuth(180)  # the shared camera: all views turn
    behind = grab_views(compare.viewports, compare.scenes)
    compare.viewports[0].plotter.camera.Azimuth(180)
    for img, back in zip(images, behind, strict=True):
        counts, counts_back = _classify(img), _classify(back)
        assert counts["blue"] + counts_back["blue"] > 200, (counts, counts_back)
        assert counts["orange"] + counts_back["orange"] > 200, (counts, counts_back)
    # dragging in the first view rotates the third
    first = compare.viewports[0].widget
    before = compare.viewports[2].render_now()
    start = QtCore.QPoint(first.width() // 2, first.height() // 2)
    qtbot.mousePress(first, QtCore.Qt.MouseButton.LeftButton, pos=start)
    for step in range(1, 6):
        qtbot.mouseMove(first, start + QtCore.QPoint(20 * step, 0))
    qtbot.mouseRelease(first, QtCore.Qt.MouseButton.LeftButton, pos=start + QtCore.QPoint(100, 0))
    after = compare.viewports[2].render_now()
    assert np.mean(np.any(before != after, axis=2)) > 0.01
    assert window.picked is None  # a drag is not a click
    out = compare.export_screenshot(tmp_path / "compare.png")
    gaps = 4 * (len(images) - 1)
    assert Image.open(out).size[0] == sum(img.shape[1] for img in images) + gaps


def test_comparison_of_distances(window, spot_path):
    window.open_mesh(spot_path)
    window.compute("laplacian", k=20, wait=True)
    window.compute("shells", k=20, wait=True)
    window.pick_vertex(500)
    compare = window.open_comparison(["vibration", "hks"])
    drawn = []
    for scene, kind in zip(compare.scenes, ("vibration", "hks"), strict=True):
        d = window.distance_map(kind)
        # coloured by the distance, or by its spread scale (the share of area below it)
        expected = d if scene.scale is None else np.interp(d, *scene.scale)
        np.testing.assert_allclose(scene.surface.point_data["field"], expected)
        drawn.append(d)
    vib, hks = drawn
    assert not np.allclose(vib / vib.max(), hks / hks.max())


def test_export_field_as_vtp(window, spot_path, tmp_path):
    import pyvista as pv

    window.open_mesh(spot_path)
    spec = window.compute("laplacian", k=10, wait=True)
    window.show_mode(3)
    out = window.export_field(tmp_path / "mode.vtp")
    back = pv.read(out)
    name = back.point_data.keys()[0]
    np.testing.assert_allclose(back.point_data[name], spec.mode(3))
    # a threshold map's title holds "<", which VTK wrote unescaped into the XML
    window.pick_vertex(700)
    d = window.show_distance("hks", display="threshold", share=0.3)
    out = window.export_field(tmp_path / "map.vtp")
    back = pv.read(out)
    name = back.point_data.keys()[0]
    assert "<" not in name and name.startswith("Heat_kernel_distance")
    np.testing.assert_allclose(back.point_data[name], d)
    # the name is the distance's, not the threshold's (it changed with the slider)
    assert name == "Heat_kernel_distance"


def test_corrupted_cache_entry_is_recomputed(window, spot_path):
    window.open_mesh(spot_path)
    first = window.compute("laplacian", k=9, wait=True)
    path = window.cache.path(window.state.compute_mesh(), "laplacian", 9, 1.0, 1.0)
    assert path.is_file()
    path.write_bytes(b"not a spectrum at all")
    window.open_mesh(spot_path)
    again = window.compute("laplacian", k=9, wait=True)  # recomputed, not trusted
    np.testing.assert_array_equal(first.eigenvalues, again.eigenvalues)
    import modalviewer as mv

    assert mv.load_spectrum(path).k == 9  # and the entry was rewritten


def test_export_into_an_impossible_folder_gives_a_clear_error(window, spot_path, tmp_path):
    window.open_mesh(spot_path)
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    with pytest.raises(OSError):
        window.export_screenshot(blocker / "fig.png")
    assert not list(tmp_path.glob("**/*.png"))


def test_coarse_to_fine_option(window):
    import json
    from pathlib import Path

    import modalviewer as mv

    assets = Path(__file__).resolve().parents[2] / "assets"
    window.open_mesh(assets / "demo_hand.obj")
    window.state.compute_settings.coarse = True
    spec = window.compute("shells", k=60, wait=True)
    assert spec.n_vertices == window.mesh.n_vertices
    assert spec.parameters["coarse_vertices"] < 0.25 * window.mesh.n_vertices
    tip = json.loads((assets / "demo_landmarks.json").read_text())["demo_hand"]["finger1"]
    window.pick_vertex(tip)
    coarse_d = window.distance_map()
    full = mv.compute_spectrum(window.mesh, "shells", k=60)
    full_d = mv.multiscale_distance(full, tip)
    assert np.corrcoef(coarse_d, full_d)[0, 1] > 0.85


def test_too_large_computation_is_refused_up_front(window, spot_path, monkeypatch):
    from modalviewer.core import memory
    from modalviewer.gui import main_window

    window.open_mesh(spot_path)
    monkeypatch.setattr(memory, "physical_memory_mb", lambda: 64.0)  # 64 MiB
    with pytest.raises(main_window.ComputeError, match="GiB of memory"):
        window.compute("shells", k=300, wait=True)
    assert "Coarse-to-fine" in window.last_error and not window.busy
    assert "modes fit" in window.last_error


def test_closing_during_a_computation_stops_it(qtbot, tmp_path):
    from modalviewer.gui import MainWindow

    win = MainWindow()
    qtbot.addWidget(win)
    win.show()
    win.open_mesh(_big_mesh_file(tmp_path))
    win.compute("shells", k=200, wait=False)
    job = win.running_job
    qtbot.wait(800)
    win.close()  # cancels and waits for the worker
    assert job.join(0)  # the worker has stopped
    assert not win.busy


def test_isolines_match_vtk_contour_filter():
    import pyvista as pv

    from modalviewer.core.primitives import icosphere
    from modalviewer.scene.isolines import line_polydata, segments

    mesh = icosphere(4)
    v, f = mesh.vertices, mesh.faces
    values = np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1]) + 0.5 * v[:, 2]
    levels = np.linspace(values.min(), values.max(), 14)[1:-1]
    ours = line_polydata(*segments(v, f, values, levels, displacement=2.0 * v)[:2])
    poly = pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
    poly.point_data["field"] = values
    ref = poly.contour(isosurfaces=list(levels), scalars="field")

    def total_length(lines: pv.PolyData) -> float:
        total, i, cells, pts = 0.0, 0, lines.lines, lines.points
        while i < len(cells):
            ids = cells[i + 1 : i + 1 + cells[i]]
            total += np.linalg.norm(np.diff(pts[ids], axis=0), axis=1).sum()
            i += cells[i] + 1
        return total

    assert ours.n_lines > 500
    np.testing.assert_allclose(total_length(ours), total_length(ref), rtol=1e-9)
    # every line point lies on the sphere's surface and carries its interpolated value
    r = np.linalg.norm(ours.points, axis=1)
    assert r.max() <= 1.0 + 1e-12
    np.testing.assert_allclose(ours.point_data["displacement"], 2.0 * ours.points, atol=1e-12)


def test_shells_on_an_inconsistently_oriented_mesh_fail_with_a_message(window):
    """The manifold and orientation checks run in the worker; the message reaches the user."""
    from modalviewer.core.mesh import Mesh
    from modalviewer.core.primitives import grid_plate
    from modalviewer.gui import main_window

    plate = grid_plate(6, 6)
    v = np.vstack([plate.vertices, [[0.5, 0.5, 1.0]]])
    fin = [[0, 1, plate.n_vertices]]  # a fin on the boundary edge (0, 1), against its face
    window.set_mesh(Mesh(v, np.vstack([plate.faces, fin])))
    with pytest.raises(main_window.ComputeError, match="not consistently oriented"):
        window.compute("shells", k=6, wait=True)
    assert "cannot run" in window.last_error and not window.busy
    spec = window.compute("laplacian", k=6, wait=True)  # the Laplacian still works
    assert spec.k == 6 and window.state.display.kind == "mode"


def test_spectrum_plot_leaves_room_for_its_axis_labels(window):
    plot = window.modes_panel.spectrum_plot
    plot.resize(300, 140)
    plot.set_data(np.arange(5), [-4.75e-8, 1.0, 2.0, 3.0, 5470.0])
    plot.grab()
    frame = plot.ax.patch.get_window_extent()
    lo, hi = plot.ax.get_ylim()
    labels = [
        label.get_window_extent()
        for value, label in zip(plot.ax.get_yticks(), plot.ax.get_yticklabels(), strict=True)
        if lo <= value <= hi and label.get_text()
    ]
    assert len(labels) >= 2
    # every value label whole in the widget, left of the frame
    assert all(0 <= box.x0 and box.x1 < frame.x0 for box in labels)


def test_an_idle_window_does_not_render(window, spot_path, qtbot):
    # pyvistaqt's QtInteractor re-renders five times a second by default (auto_update),
    # which cost a full core in software OpenGL; the viewer renders only on change.
    window.open_mesh(spot_path)
    window.compute("laplacian", k=8, wait=True)
    window.show_mode(3)
    window.viewport.render_now()
    qtbot.wait(300)  # let the paint events already queued by these changes arrive
    renders = []
    tag = window.plotter.ren_win.AddObserver("StartEvent", lambda *_: renders.append(1))
    qtbot.wait(1500)
    window.plotter.ren_win.RemoveObserver(tag)
    assert len(renders) == 0
    window.show_mode(4)  # a change does render
    window.viewport.render_now()
    assert window.scene.iso_actor.GetVisibility() and window.scene.isolines.n_points > 0


def test_a_narrow_view_keeps_the_whole_mesh_in_sight(window, spot_path, qtbot):
    """The view angle applies to the smaller side of the view, so a mesh fitted in a wide
    view stays whole when the view is made narrower than tall (it was cropped at the
    sides until the camera was reset)."""
    assert window.open_mesh(spot_path)
    window.state.style.colorbar = False

    def surface_columns():
        img = window.viewport.render_now().astype(int)
        surface = (img < 235).any(axis=2)
        h, w = surface.shape
        band = surface[h // 6 : h - h // 6]  # leave out the legend at the top
        cols = np.flatnonzero(band.any(axis=0))
        return cols, w, h

    window.viewport.widget.setFixedSize(600, 400)
    qtbot.wait(50)
    window.scene_view.drawing.reset_camera()  # fitted in a wide view
    cols, w, h = surface_columns()
    assert (w, h) == (600, 400)
    assert cols.size > 0 and cols.min() > 2 and cols.max() < w - 3
    window.viewport.widget.setFixedSize(220, 520)
    qtbot.wait(50)
    cols, w, h = surface_columns()
    assert (w, h) == (220, 520)
    assert cols.size > 0
    assert cols.min() > 2 and cols.max() < w - 3, (cols.min(), cols.max(), w)


def test_the_3d_view_keeps_a_usable_size_in_a_narrow_window(window, spot_path, qtbot):
    """Found under Xvfb: at 700 x 600 the docks kept their width and left the 3D view
    about 45 pixels wide, its legend one word per line over the mesh."""
    assert window.open_mesh(spot_path)
    window.resize(500, 500)
    qtbot.wait(100)
    view = window.viewport.widget
    assert view.width() >= 320 and view.height() >= 240, (view.width(), view.height())


def test_after_a_distance_map_fails_the_panel_says_so_and_another_kind_shows(window, qtbot):
    # a vibration map whose shells spectrum failed left "The map follows when its
    # spectrum is computed" with nothing computing, and another kind started nothing
    from modalviewer.core.mesh import Mesh
    from modalviewer.core.primitives import grid_plate

    plate = grid_plate(6, 6)
    v = np.vstack([plate.vertices, [[0.5, 0.5, 1.0]]])
    fin = [[0, 1, plate.n_vertices]]  # the shells refuse it: not consistently oriented
    window.set_mesh(Mesh(v, np.vstack([plate.faces, fin])))
    window.compute("laplacian", k=12, wait=True)
    window.pick_vertex(20)
    window.show_distance("vibration")
    panel = window.distances_panel
    assert panel.threshold_label.text() == "The map follows when its spectrum is computed"
    qtbot.waitUntil(lambda: not window.busy, timeout=60000)
    assert "not consistently oriented" in window.last_error
    assert panel.threshold_label.text() == "Show distance (D) computes the spectrum it needs"
    assert window.state.display.kind == "mode"
    panel.kind_combo.setCurrentIndex(panel.kind_combo.findData("hks"))  # as a user would
    qtbot.waitUntil(lambda: window.state.display.kind == "distance", timeout=60000)
    assert window.state.display.distance_kind == "hks"
    assert panel.threshold_label.text().startswith("< ")


def test_the_first_modes_are_drawn_while_the_others_converge(window, spot_path, monkeypatch, qtbot):
    """The window draws the first modes that converged, with the Modes panel saying how
    many of how many are in, before the computation ends."""
    import threading

    from modalviewer import spectra as spectra_module

    go = threading.Event()
    solve = spectra_module.compute_spectrum

    def paused(*args, on_modes=None, **kwargs):
        def hand_over(spec):
            on_modes(spec)
            if spec.k >= 12 and not spec.is_complete:
                go.wait(60)

        return solve(*args, on_modes=hand_over, **kwargs)

    monkeypatch.setattr(spectra_module, "compute_spectrum", paused)
    assert window.open_mesh(spot_path)
    window.state.style.colorbar = False
    try:
        window.compute("laplacian", k=60, wait=False)
        qtbot.waitUntil(lambda: window.state.modes_ready("laplacian")[0] >= 12, timeout=60000)
        ready, asked = window.state.modes_ready("laplacian")
        assert 12 <= ready < asked == 60
        assert window.viewer.computing("laplacian")  # the solve waits for the test
        assert window.state.display.kind == "mode" and window.state.display.mode == 1
        counts = _both_sides(window)
        assert counts["blue"] > 2000 and counts["orange"] > 2000, counts
        assert f"{ready} of 60 modes ready" in window.modes_panel.eigen_label.text()
    finally:
        go.set()
    qtbot.waitUntil(lambda: window.state.modes_ready("laplacian")[0] >= 60, timeout=60000)
    assert window.state.modes_ready("laplacian") == (60, 60)
    assert "modes ready" not in window.modes_panel.eigen_label.text()
