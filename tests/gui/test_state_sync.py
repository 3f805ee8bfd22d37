"""The window around the state model: jobs keep to themselves, panels agree with the
picture, keys go to the focused widget, sessions restore the picture.  Each numbered
test is one of the problems the state model was built to fix."""

import configparser

import numpy as np
import pytest
from qtpy import QtCore, QtGui, QtWidgets

from modalviewer.core.laplacian import lumped_masses
from modalviewer.viewer import wording

pytestmark = pytest.mark.gui


def test_1_a_waiting_compute_returns_its_own_spectrum(window, spot_path, qtbot):
    """A shells request arriving while a Laplacian request waits (as a click on the
    surface does) used to cancel it and hand its spectrum to the Laplacian's caller."""
    window.open_mesh(spot_path)
    QtCore.QTimer.singleShot(100, lambda: window.compute("shells", k=20, wait=False))
    spec = window.compute("laplacian", k=237, wait=True)
    assert spec.operator == "laplacian" and spec.k == 237
    qtbot.waitUntil(lambda: not window.busy, timeout=120000)
    assert window.spectra["shells"].k == 20  # the other request was not lost either


def test_2_the_modes_panel_does_not_name_a_mode_that_is_not_shown(window, spot_path, qtbot):
    window.open_mesh(spot_path)
    window.compute("laplacian", k=40, wait=True)
    window.show_mode(31)
    assert window.modes_panel.eigen_label.text().startswith("lambda_31 = ")
    window.pick_vertex(700)
    window.show_distance("vibration", display="threshold", share=0.3)
    qtbot.waitUntil(lambda: window.state.display.kind == "distance", timeout=120000)
    label = window.modes_panel.eigen_label.text()
    assert "lambda_31" not in label and label.startswith("Not shown")
    assert "vibration distance" in label
    assert window.status_line.text().startswith("blue: vibration distance <")
    assert window.distances_panel.display_combo.currentData() == "threshold"


def test_3_compare_asks_before_computing_and_never_changes_the_main_window(
    window, spot_path, qtbot, monkeypatch, tmp_path
):
    window.open_mesh(spot_path)
    window.compute("modified_dirichlet", k=20, wait=True)
    window.state.set_display(distance_kind="feature")  # a pick then needs no new spectrum
    window.pick_vertex(50)
    window.show_distance("feature", display="threshold", share=0.2)
    before = window.state.display
    # the menu's Ctrl+1 with the question answered No: nothing starts
    assert window.open_comparison(["laplacian", "modified_dirichlet"], wait=False) is None
    assert not window.busy and "laplacian" not in window.spectra
    # answered Yes: computed in the background, then opened; the main view is unchanged
    monkeypatch.setenv("MODALVIEWER_ASSUME_YES", "1")
    window.open_comparison(["laplacian", "modified_dirichlet"], wait=False)
    qtbot.waitUntil(lambda: window.compare is not None, timeout=120000)
    assert window.state.display == before
    compare = window.compare
    assert compare.comparison.mode_index == 1  # the first non-zero mode, not the constant mode 0
    assert "mode 1," in compare.titles[0].text()
    field = np.array(compare.scenes[0].surface.point_data["field"])
    assert np.ptp(field) > 0  # not one solid colour
    compare.show()
    qtbot.waitExposed(compare)
    qtbot.keyClick(compare, QtCore.Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: window.compare is None, timeout=5000)
    window.open_comparison(["laplacian", "modified_dirichlet"])
    compare = window.compare
    compare.show()
    qtbot.waitExposed(compare)
    qtbot.keyClick(compare, QtCore.Qt.Key.Key_W, QtCore.Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: window.compare is None, timeout=5000)
    # a key pressed in one of its 3D views reaches the window too
    window.open_comparison(["laplacian", "modified_dirichlet"])
    compare = window.compare
    compare.show()
    qtbot.waitExposed(compare)
    view = compare.viewports[0].widget
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Right)
    assert compare.comparison.mode_index == 2
    import os

    old = os.umask(0o022)
    try:
        out = compare.export_screenshot(tmp_path / "pair.png")
    finally:
        os.umask(old)
    assert (out.stat().st_mode & 0o777) == 0o644  # mkstemp alone gave 0600
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: window.compare is None, timeout=5000)


def test_4_arrow_keys_move_a_focused_slider_not_the_mode(window, spot_path, qtbot):
    window.open_mesh(spot_path)
    window.compute("laplacian", k=30, wait=True)
    window.show_mode(3)
    window.state.set_display(distance_display="threshold")
    slider = window.distances_panel.threshold_slider
    slider.setFocus()
    qtbot.waitUntil(slider.hasFocus, timeout=2000)
    start = slider.value()
    for _ in range(5):
        qtbot.keyClick(slider, QtCore.Qt.Key.Key_Right)
    assert slider.value() == start + 5 * slider.singleStep()
    assert window.state.display.mode == 3
    # in the 3D view the arrows do step modes
    view = window.viewport.widget
    view.setFocus()
    qtbot.waitUntil(view.hasFocus, timeout=2000)
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Right)
    assert window.state.display.kind == "mode" and window.state.display.mode == 4


def test_5_status_and_legend_follow_the_threshold_slider(window, spot_path):
    window.open_mesh(spot_path)
    window.compute("modified_dirichlet", k=30, wait=True)
    window.pick_vertex(1000)
    d = window.show_distance("feature", display="threshold", share=0.5)
    slider = window.distances_panel.threshold_slider
    for position in (50, 200, 600):  # share of the surface, in thousandths
        slider.setValue(position)  # what dragging does
        thr = window.state.display.threshold * d.max()
        areas = lumped_masses(window.state.mesh)
        share = 100.0 * areas[d <= thr].sum() / areas.sum()
        assert share == pytest.approx(position / 10, abs=1.0)
        text = f"{share:.1f} % of the surface"
        assert text in window.status_line.text()
        assert text in window.scene.legend_text
        assert f"{thr:.4g}" in window.distances_panel.threshold_label.text()
        field = np.asarray(window.scene.surface.point_data["field"])
        np.testing.assert_array_equal(field, d)  # coloured blue up to thr by the table


def test_6_a_headless_window_writes_no_desktop_settings(qtbot, tmp_path, monkeypatch):
    from modalviewer.gui import MainWindow

    ini = tmp_path / "headless.ini"
    monkeypatch.setenv("MODALVIEWER_SETTINGS", str(ini))
    assert QtWidgets.QApplication.platformName() == "offscreen"
    win = MainWindow()
    qtbot.addWidget(win)
    win.resize(900, 500)
    win.show()
    win.close()
    parser = configparser.ConfigParser()
    parser.read(ini)
    assert not parser.has_section("window")
    assert not ini.exists() or "geometry" not in ini.read_text()


def test_a_restored_session_draws_the_same_picture(qtbot, spot_path, tmp_path):
    from modalviewer.gui import MainWindow

    first = MainWindow()
    qtbot.addWidget(first)
    first.resize(1000, 700)
    first.show()
    qtbot.waitExposed(first)
    first.open_mesh(spot_path)
    first.compute("modified_dirichlet", k=30, wait=True)
    first.show_mode(7)
    first.state.style.isolines = 5
    first.pick_vertex(1234)
    first.show_distance("feature", display="threshold", share=0.25)
    first.plotter.camera.Azimuth(70)
    first.plotter.camera.Elevation(20)
    image = first.viewport.render_now()
    session = first.save_session(tmp_path / "s.json")
    first.close()

    second = MainWindow()
    qtbot.addWidget(second)
    second.resize(1000, 700)
    second.show()
    qtbot.waitExposed(second)
    assert second.open_session(session, wait=True) == []
    again = second.viewport.render_now()
    assert again.shape == image.shape
    differ = np.mean(np.any(np.abs(again.astype(int) - image.astype(int)) > 8, axis=2))
    assert differ < 0.002, differ
    assert second.status_line.text() == wording.summary(second.state)
    assert "feature distance" in second.status_line.text()
    # M shows the mode last shown before the distance, as before the restart
    assert second.modes_panel.mode_spin.value() == 7
    second.viewer.show_current_mode()
    assert second.state.display.kind == "mode" and second.state.display.mode == 7
    second.close()


def test_the_app_restores_a_session_from_the_command_line(tmp_path, spot_path):
    import os
    import subprocess
    import sys

    from PIL import Image

    from modalviewer.core.cache import SpectrumCache
    from modalviewer.viewer import ViewerModel
    from modalviewer.viewer.session import save_session

    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(spot_path)
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=True))
    model.state.show_mode(5)
    session = save_session(model.state, tmp_path / "s.json")
    out = tmp_path / "shot.png"
    env = dict(os.environ, MODALVIEWER_CACHE=str(tmp_path / "cache"), QT_QPA_PLATFORM="offscreen")
    run = subprocess.run(
        [sys.executable, "-m", "modalviewer", "--session", str(session), "--screenshot", str(out)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    assert ((b > r + 60) & (b > g + 20)).sum() > 1000  # mode 5 in blue and orange
    assert ((r > b + 80) & (g > b + 20)).sum() > 1000


def test_clear_cache_from_the_window(window, spot_path):
    window.open_mesh(spot_path)
    window.compute("laplacian", k=10, wait=True)
    assert window.cache.size_bytes() > 0
    freed = window.clear_cache()
    assert freed > 0 and window.cache.size_bytes() == 0
    assert window.spectra["laplacian"].k == 10  # the spectrum on screen stays


def test_keep_the_largest_component_from_the_window(window, qtbot, tmp_path):
    """Mesh > Keep the largest component through the window: the repaired mesh replaces
    the loaded one and its report is shown, with no error (the job-finished handler took
    every finished job for a spectrum job: 'Mesh' object is not subscriptable, and the
    mesh kept its three components)."""
    import modalviewer as mv
    from modalviewer.core.primitives import icosphere, torus

    big, small = torus(24, 10), icosphere(1)
    big = mv.Mesh(3.0 * big.vertices, big.faces)  # the largest by area too
    parts = [big, small, small]
    offsets = [(0.0, 0.0, 0.0), (6.0, 0.0, 0.0), (-6.0, 0.0, 0.0)]
    vertices, faces, base = [], [], 0
    for part, offset in zip(parts, offsets, strict=True):
        vertices.append(part.vertices + offset)
        faces.append(part.faces + base)
        base += part.n_vertices
    path = tmp_path / "three.obj"
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in np.vstack(vertices)]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.vstack(faces)]
    path.write_text("\n".join(lines) + "\n")
    assert window.open_mesh(path)
    assert window.mesh.n_components == 3
    errors = []
    window.viewer.events.error.connect(lambda *args: errors.append(args))
    window.repair_mesh("largest_component", wait=False)
    job = window.viewer.jobs.jobs[-1] if window.viewer.jobs.jobs else None
    qtbot.waitUntil(lambda: window.mesh.n_components == 1, timeout=30000)
    assert window.mesh.n_vertices == big.n_vertices
    assert isinstance(window.mesh, mv.Mesh)
    assert errors == []
    assert "component" in window.statusBar().currentMessage()
    # a scripted wait on such a job ends
    if job is not None:
        assert window.wait_for(job).status == "done"


def test_ctrl_arrows_step_modes_from_a_number_field(window, spot_path, qtbot):
    """README: Ctrl+Left/Right step modes anywhere.  Found under Xvfb: with the focus in
    a spin box (Modes k, Bending weight) the field took them to move its cursor."""
    window.open_mesh(spot_path)
    window.compute("laplacian", k=30, wait=True)
    window.show_mode(3)
    for field in (window.compute_panel.k_spin, window.modes_panel.iso_spin):
        field.setFocus()
        qtbot.waitUntil(field.hasFocus, timeout=2000)
        before = field.value()
        mode = window.state.display.mode
        target = QtWidgets.QApplication.focusWidget()  # the spin box's line edit
        qtbot.keyClick(target, QtCore.Qt.Key.Key_Right, QtCore.Qt.KeyboardModifier.ControlModifier)
        assert window.state.display.mode == mode + 1
        qtbot.keyClick(target, QtCore.Qt.Key.Key_Left, QtCore.Qt.KeyboardModifier.ControlModifier)
        assert window.state.display.mode == mode
        assert field.value() == before


def test_the_mesh_info_grows_with_its_text(window, spot_path, qtbot, tmp_path):
    """Found under Xvfb: opening a mesh of three components after a plain one left the
    Compute panel's mesh text (now six lines) at the old height, cut at top and bottom."""
    from modalviewer.core.primitives import icosphere

    a, b = icosphere(2), icosphere(1)
    path = tmp_path / "two.obj"
    vertices = np.vstack([a.vertices, b.vertices + [3.0, 0.0, 0.0]])
    faces = np.vstack([a.faces, b.faces + a.n_vertices])
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in faces]
    path.write_text("\n".join(lines) + "\n")
    window.open_mesh(spot_path)
    qtbot.wait(50)
    window.open_mesh(path)
    label = window.compute_panel.mesh_info
    qtbot.waitUntil(lambda: "connected components" in label.text(), timeout=2000)
    qtbot.wait(100)
    needed = label.heightForWidth(label.width())
    assert label.height() >= needed, (label.height(), needed, label.width())


def test_a_narrow_status_line_elides_its_text(window, spot_path, qtbot):
    """Found under Xvfb: the status line's text was cut off mid-word at the right
    ("...(normal componen"); it now ends in an ellipsis, the whole text in its tooltip."""
    window.open_mesh(spot_path)
    window.compute("laplacian", k=20, wait=True)
    window.show_mode(3)
    line = window.status_line
    assert line.toolTip() == line.text() == wording.summary(window.state)
    line.setFixedWidth(160)
    qtbot.wait(50)
    img = line.grab().toImage()
    w, h = img.width(), img.height()
    ink = [x for x in range(w) for y in range(h) if QtGui.QColor(img.pixel(x, y)).lightness() < 100]
    assert ink, "no text drawn"
    # the text stops short of the frame (an ellipsis), instead of running into it
    assert max(ink) < w - 5, (max(ink), w)


def test_the_status_bar_ends_every_job_and_the_colour_bar_tick_matches_at_start(window, spot_path):
    """Found under Xvfb: after the shape pair's spectra (jobs without a spectrum key) the
    status bar kept "Computing ... of B (...)" for minutes; at start-up the colour bar was
    shown but its View menu entry unticked, so the first B did nothing."""
    assert window.state.style.colorbar and window.colorbar_action.isChecked()
    window.colorbar_action.trigger()  # what B does
    assert not window.state.style.colorbar
    window.colorbar_action.trigger()
    assert window.state.style.colorbar
    window.open_mesh(spot_path)
    spec = window.compute("laplacian", k=10, wait=True)
    bar = window.statusBar()
    for result, description in (((spec, None), "spectrum of B"), (42, "other work")):
        job = window.viewer.jobs.submit(
            lambda p, c, r=result: r, ("test", description), description, None
        )
        window.wait_for(job)
        message = bar.currentMessage()
        assert not message.startswith("Computing"), message
        assert description in message


def test_a_closed_panel_comes_back_from_the_view_menu(window):
    """Found under Xvfb: a closed dock could only be restored from a dock title's context
    menu, which is gone when all docks are closed."""
    view = next(a.menu() for a in window.menuBar().actions() if a.text() == "&View")
    panels = next(a.menu() for a in view.actions() if a.text() == "&Panels")
    names = [a.text() for a in panels.actions()]
    assert names == ["Compute", "Modes", "Distances and signatures"]
    dock = next(d for d in window.findChildren(QtWidgets.QDockWidget) if d.windowTitle() == "Modes")
    dock.close()
    assert dock.isHidden()
    panels.actions()[1].trigger()
    assert not dock.isHidden()


def test_compute_options_and_the_colour_bar_are_remembered(window, qtbot):
    """Found under Xvfb: Coarse-to-fine and the colour bar came back at their defaults
    after a restart (settings.ini held operator, weights and rescale only).  A settings
    file that still names the removed preview options starts without them."""
    from modalviewer.gui import MainWindow, window_settings

    window.state.compute_settings.coarse = True
    window.state.compute_settings.operator = "laplacian"
    window.state.style.colorbar = False
    window.state.set_color_range("limits", (-0.5, 2.0))
    window.state.style.log_signature = True
    window.remember_settings = True  # as on a desktop
    window.settings.setValue("compute/preview_only", "true")  # an older version's option
    window.settings.setValue("compute/preview", "false")
    window_settings.save(window)
    assert not window.settings.contains("compute/preview_only")
    window.settings.setValue("compute/preview_only", "true")  # left by an older version
    window.settings.sync()
    again = MainWindow()
    qtbot.addWidget(again)
    c = again.state.compute_settings
    assert c.coarse is True and c.operator == "laplacian"
    assert not hasattr(c, "preview_only") and not hasattr(again.compute_panel, "preview_check")
    assert again.state.style.colorbar is False
    assert again.state.style.color_range == "limits"
    assert again.state.style.color_limits == (-0.5, 2.0)
    assert again.state.style.log_signature is True
    assert not again.colorbar_action.isChecked()
    assert again.compute_panel.coarse_check.isChecked()
    again.compute_panel.coarse_check.click()  # the box drives the setting
    assert again.state.compute_settings.coarse is False


def test_a_combo_box_names_its_whole_item_in_its_tooltip(window):
    """The Operator box is 14 characters wide and shows "Discrete Shells, normal v..."."""
    box = window.compute_panel.operator_combo
    index = box.findData("shells_normal")
    box.setCurrentIndex(index)
    assert box.toolTip() == box.itemText(index) == "Discrete Shells, normal variations"
    colours = window.modes_panel.color_combo  # a box with a purpose keeps it below
    assert colours.toolTip() == colours.currentText() + "\nHow 3D vibration modes are shown"


def test_esc_says_what_stays_queued_also_once_the_next_job_starts(window, spot_path):
    """Found under Xvfb: "Cancelling...; 2 more queued" was replaced within 0.15 s by the
    next job's "Computing ..."."""
    window.open_mesh(spot_path)
    messages = []
    window.statusBar().messageChanged.connect(messages.append)
    first = window.viewer.request_spectrum("shells", k=30)
    window.viewer.request_spectrum("laplacian", k=15)
    last = window.viewer.request_spectrum("modified_dirichlet", k=15)
    assert window.running_job is first
    window.cancel_computation()
    assert window.statusBar().currentMessage() == (
        "Cancelled; 2 more requests queued (Ctrl+Shift+Esc cancels all)"
    )
    # a long message may be cut where the status line begins: whole in the tooltip
    assert window.statusBar().toolTip() == window.statusBar().currentMessage()
    window.wait_for(first)
    window.wait_for(last)
    assert first.status == "cancelled" and last.status == "done"
    # the next job's start keeps the note in front of its own message, once
    noted = [m for m in messages if m.startswith("Cancelled; 2 more requests queued")]
    assert [m.split(". ", 1)[1] for m in noted[1:]] == ["Computing Laplacian (cotan), 15 modes..."]


def test_a_click_that_starts_a_long_computation_says_how_long(window, spot_path, monkeypatch):
    """Found under Xvfb: a click with the default vibration distance started a 3D
    shells computation of 40 s or more at 130k vertices with only "Computing ..." on
    screen (the long-wait note came from 5 min on and was overwritten).  The time comes
    from this machine's recorded solves; with none recorded no time is shown."""
    from modalviewer.core.cache import SolveRecord
    from modalviewer.viewer import viewer

    monkeypatch.setattr(viewer, "LONG_WAIT_SECONDS", 0.0)
    window.open_mesh(spot_path)
    mesh, k = window.state.mesh, window.state.compute_settings.k
    recorded = [SolveRecord("shells", mesh.hash, mesh.n_vertices, k, 45.0)]
    monkeypatch.setattr(window.viewer.cache, "solves", lambda: recorded)
    window.state.set_display(distance_kind="vibration")
    window.pick_vertex(100)
    message = window.statusBar().currentMessage()
    assert message.startswith("Computing the spectrum for the vibration distance; ")
    assert "this will take about 45 s" in message and "Esc cancels" in message
    window.cancel_all()
    monkeypatch.setattr(window.viewer.cache, "solves", lambda: [])
    window.state.set_display(distance_kind="hks")
    window.pick_vertex(101)
    message = window.statusBar().currentMessage()
    assert message == "Computing the spectrum for the heat kernel distance...", message
    window.cancel_all()


def test_the_compute_panel_names_parts_held_at_a_vertex(window, tmp_path, qtbot):
    """A teapot whose handle meets the body at vertices had 21 zero shells modes where the
    panel promised 18."""
    from modalviewer.core.primitives import icosphere

    a = icosphere(1)
    b = -a.vertices + 2.0 * a.vertices[0]  # touches a at its vertex 0
    index = np.concatenate([[0], len(a.vertices) + np.arange(len(b) - 1)])
    vertices = np.vstack([a.vertices, b[1:]])
    faces = np.vstack([a.faces, index[a.faces[:, ::-1]]])
    path = tmp_path / "touching.obj"
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in faces]
    path.write_text("\n".join(lines) + "\n")
    window.open_mesh(path)
    label = window.compute_panel.mesh_info
    qtbot.waitUntil(lambda: "the rest only at vertices" in label.text(), timeout=2000)
    assert "1 part meets" in label.text() and "three more zero modes" in label.text()


def test_another_distance_kind_keeps_the_share_of_the_threshold_map(window, spot_path):
    """Found under Xvfb: a vibration map marking 10 % of the cow marked 0 % as a feature
    map and 98 % as a heat kernel map (the threshold was a fixed fraction of each
    kind's largest distance); the Compare window's views were almost all blue."""
    window.open_mesh(spot_path)
    for operator in ("laplacian", "modified_dirichlet"):
        window.compute(operator=operator, k=30)
    window.pick_vertex(300)
    window.show_distance(kind="hks", display="threshold")
    panel = window.distances_panel
    panel.threshold_slider.setValue(120)  # by share: 12 % of the surface
    before = window.state.derived.marked_share()
    assert before == pytest.approx(0.12, abs=0.01)
    panel.kind_combo.setCurrentIndex(panel.kind_combo.findData("feature"))
    assert window.state.display.distance_kind == "feature"
    assert window.state.derived.marked_share() == pytest.approx(before, abs=0.005)
    compare = window.open_comparison(["hks", "feature"])
    shares = [title.text().split("(")[-1] for title in compare.titles]
    assert all(text.startswith("12.") for text in shares), shares
    compare.close()


def test_choosing_the_spectrum_on_screen_again_keeps_its_mode(window, spot_path):
    """Found under Xvfb: choosing the Laplacian again in the Modes panel's Spectrum list
    (teapot, a distance map of mode 15's spectrum on screen) jumped to mode 3."""
    window.open_mesh(spot_path)
    window.compute("laplacian", k=30, wait=True)
    window.show_mode(15)
    combo = window.modes_panel.spectrum_combo
    index = combo.findData("laplacian")
    combo.activated.emit(index)
    assert window.state.display.kind == "mode" and window.state.display.mode == 15
    window.pick_vertex(800)
    window.state.set_display(kind="distance", distance_kind="hks")
    combo.activated.emit(combo.findData("laplacian"))
    assert window.state.display.kind == "mode" and window.state.display.mode == 15


def test_the_status_line_gives_room_to_a_message(window, spot_path, qtbot):
    """Found under Xvfb: "Computing Discrete Shells (3D vibrations), 100 modes; no pr..."
    was cut off by the status line beside it."""
    from modalviewer.gui.status_bar import StatusBarWidgets

    window.resize(1600, 1000)
    window.open_mesh(spot_path)
    window.compute("laplacian", k=20, wait=True)
    window.show_mode(3)
    bar, line = window.statusBar(), window.status_line
    message = "Computing Discrete Shells (3D vibrations), 100 modes; " + "x" * 60
    bar.showMessage(message)
    qtbot.wait(50)
    assert line.width() <= StatusBarWidgets.STATUS_LINE_WIDTH_BESIDE_MESSAGE
    assert bar.toolTip() == message
    bar.clearMessage()
    qtbot.wait(50)
    assert line.maximumWidth() == StatusBarWidgets.STATUS_LINE_WIDTH


def test_preferences_are_written_soon_after_they_change(window, qtbot):
    """Found under Xvfb: after the process was killed, the next start had forgotten the
    operator (settings.ini held [files] only): preferences were written on quit alone."""
    from modalviewer.gui import MainWindow

    window.remember_settings = True  # as on a desktop
    window.state.compute_settings.operator = "shells_normal"
    window.state.compute_settings.coarse = True
    qtbot.waitUntil(
        lambda: window.settings.value("compute/operator") == "shells_normal", timeout=3000
    )
    again = MainWindow()  # no closeEvent of the first window: as after a kill
    qtbot.addWidget(again)
    assert again.state.compute_settings.operator == "shells_normal"
    assert again.state.compute_settings.coarse is True


def test_the_computations_panel_keeps_how_the_last_computation_ended(window, spot_path, qtbot):
    """Found under Xvfb: the "... in N s" message gave way to the next one within
    seconds, and the time was lost; the Computations panel keeps the last one."""
    from types import SimpleNamespace

    from modalviewer.viewer.wording import ended_text

    panel = window.jobs_panel
    assert not panel.last.isVisibleTo(window)
    window.open_mesh(spot_path)
    window.compute("laplacian", k=10, wait=True)
    qtbot.waitUntil(lambda: panel.last.text() != "", timeout=60000)
    assert panel.last.text().startswith("Last: Laplacian (cotan), 10 modes in ")
    assert panel.last.text().endswith(" s") and panel.last.isVisibleTo(window)
    given_up = SimpleNamespace(status="cancelled", description="X", error=None)
    assert ended_text(given_up) == "X: cancelled"
    given_up.error = "superseded: another mesh was opened"
    assert ended_text(given_up) == "X: superseded: another mesh was opened"


def test_modes_k_takes_any_number_typed(window, spot_path, qtbot):
    """Found under Xvfb: typing 5000 in Modes k left 500 (the box stopped at 2000 and
    dropped the last digit unsaid).  A request for more modes than the mesh has gets
    them all and says so; one that would not fit is refused by the memory check."""
    window.open_mesh(spot_path)
    field = window.compute_panel.k_spin
    field.setFocus()
    qtbot.waitUntil(field.hasFocus, timeout=2000)
    field.selectAll()
    qtbot.keyClicks(QtWidgets.QApplication.focusWidget(), "5000")
    qtbot.keyClick(QtWidgets.QApplication.focusWidget(), QtCore.Qt.Key.Key_Tab)
    assert field.value() == 5000
    assert window.state.compute_settings.k == 5000


def test_the_computations_panel_shows_what_the_status_line_said_whole(window, qtbot):
    """Found under Xvfb: the status bar cuts long messages (the expected wait); a running
    job's row in the Computations panel shows them whole."""
    from modalviewer.viewer.jobs import RUNNING, Job

    panel = window.jobs_panel
    job = Job(lambda *_: None, "key", "Discrete Shells (3D vibrations), 400 modes")
    job.status, job.stage, job.fraction = RUNNING, "factorising", 0.3
    long = (
        "Discrete Shells (3D vibrations), 400 modes: this will take about 3 min (Esc "
        "cancels; Coarse-to-fine is much faster)."
    )
    job.said = [long]
    panel._on_changed(job)
    label = panel.rows[job.id][1]
    assert label.text() == f"{long}\nfactorising 30 %"
    job.status = "done"
    panel._on_changed(job)
    assert job.id not in panel.rows


def test_a_typed_t1_alone_takes_the_default_t2_and_a_reversed_range_is_said(
    window, spot_path, qtbot
):
    # t1 typed with t2 left at its default was ignored, and t1 > t2 too, without a word
    window.open_mesh(spot_path)
    window.compute("laplacian", k=30, wait=True)
    window.pick_vertex(700)
    window.show_distance("hks")
    qtbot.waitUntil(lambda: window.state.display.kind == "distance", timeout=120000)
    panel = window.distances_panel
    from modalviewer.core.signatures import default_times

    default = default_times(window.state.spectrum("laplacian"))
    t1 = 0.1 * float(default[-1])
    panel.t1_edit.setText(f"{t1:.6g}")
    panel.t1_edit.editingFinished.emit()
    assert window.state.t_range == pytest.approx((t1, float(default[-1])), 1e-5)
    assert panel.range_label.text() == ""
    panel.t1_edit.setText(f"{10 * default[-1]:g}")
    panel.t1_edit.editingFinished.emit()
    assert window.state.t_range == pytest.approx((t1, float(default[-1])), 1e-5)  # kept
    assert panel.range_label.text().startswith("t1 must be above 0 and below t2")
    panel.t2_edit.setText(f"{0.5 * default[-1]:g}")
    panel.t2_edit.editingFinished.emit()  # t1 still above t2: said again, nothing taken
    assert window.state.t_range == pytest.approx((t1, float(default[-1])), 1e-5)
    panel.t1_edit.clear()  # t1 back to its default, t2 typed
    panel.t1_edit.editingFinished.emit()
    assert window.state.t_range == pytest.approx((float(default[0]), 0.5 * default[-1]), 1e-5)
    panel.t2_edit.clear()  # both empty: the default range
    panel.t2_edit.editingFinished.emit()
    assert window.state.t_range is None and panel.range_label.text() == ""


def test_a_session_restored_with_changes_says_so_in_a_box(
    window, spot_path, tmp_path, monkeypatch, qtbot
):
    # the note (mesh changed, pick dropped) was shown in the status bar, where the
    # computation's status replaced it within half a second
    import shutil

    from modalviewer.core.primitives import icosphere

    mesh_path = tmp_path / "m.obj"
    shutil.copy(spot_path, mesh_path)
    window.open_mesh(mesh_path)
    window.compute("laplacian", k=12, wait=True)
    window.pick_vertex(704)
    session = window.save_session(tmp_path / "s.json")
    sphere = icosphere(2)  # 162 vertices: vertex 704 is gone
    lines = [f"v {x} {y} {z}" for x, y, z in sphere.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in sphere.faces]
    mesh_path.write_text("\n".join(lines) + "\n")
    monkeypatch.delenv("MODALVIEWER_NO_DIALOGS")
    notes = window.open_session(session, wait=True)
    assert any("704" in note for note in notes), notes
    box = window.message_box
    qtbot.waitUntil(lambda: box.isVisible(), timeout=5000)
    assert box.windowTitle() == "Session restored with changes"
    assert "704" in box.text()
    box.close()


@pytest.mark.parametrize(
    "rule, limits, expected",
    [
        ("robust", "not numbers", ("robust", None)),
        ("limits", "-1 3", ("limits", (-1.0, 3.0))),
        ("limits", "", ("auto", None)),  # the limits rule without its limits
        ("limits", "3 -1", ("auto", None)),  # not low < high
        ("brightest", "", ("auto", None)),  # a rule not offered
    ],
)
def test_a_damaged_colour_range_setting_starts_with_the_automatic_range(
    qtbot, rule, limits, expected
):
    from modalviewer.gui import MainWindow
    from modalviewer.gui.window_settings import settings

    saved = settings()
    saved.setValue("view/color_range", rule)
    saved.setValue("view/color_limits", limits)
    saved.sync()
    window = MainWindow()
    qtbot.addWidget(window)
    style = window.state.style
    assert (style.color_range, style.color_limits) == expected
    assert window.color_range_actions[expected[0]].isChecked()
