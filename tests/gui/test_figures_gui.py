"""Figures from the real window: the export dialog's width and height, the shape clear of
the legend whatever the window's size, no pick marker on a mode's picture, File > Export
animation and the other File exports."""

import numpy as np
import pytest
from PIL import Image
from qtpy import QtCore, QtWidgets

from modalviewer.gui.viewport import grab_views
from modalviewer.scene.export import grab
from modalviewer.scene.framing import overlay_boxes
from modalviewer.scene.offscreen import OffscreenRenderer

pytestmark = pytest.mark.gui


def _magenta(img) -> int:
    """Pixels of the pick marker's colour, shaded: red and blue well above green."""
    r, g, b = (img[..., i].astype(int) for i in range(3))
    return int(((r - g > 90) & (b - g > 40)).sum())


def _shells_mode_with_a_pick(window, spot_path, qtbot):
    window.resize(964, 350)
    qtbot.wait(50)
    assert window.open_mesh(spot_path)
    window.compute("shells", k=12, wait=True)
    window.show_mode(8)
    w, h = window.viewport.widget.width(), window.viewport.widget.height()
    window.viewport.render_now()
    vertex = window.scene.vertex_at_display(w / 2, h / 2)
    assert vertex is not None
    window.viewer.pick_vertex(vertex, show=False)  # the mode stays on screen
    assert window.state.display.kind == "mode"
    assert _magenta(window.viewport.render_now()) > 0  # the marker is on screen


def test_a_1600x1200_export_from_a_small_window_holds_the_shape_clear_of_the_legend(
    window, spot_path, qtbot, tmp_path
):
    _shells_mode_with_a_pick(window, spot_path, qtbot)
    window.state.style.colorbar = True
    out = window.export_screenshot(tmp_path / "big.png", size=(1600, 1200))
    img = np.asarray(Image.open(out))
    assert img.shape[:2] == (1200, 1600)
    assert _magenta(img) == 0  # no marker on a mode's picture
    # the same picture without legend and bar, from the camera the export fitted
    renderer = OffscreenRenderer(window.state, (1600, 1200))
    try:
        renderer.set_camera(window.viewer.current_camera())
        renderer.frame()
        bare = grab(renderer.plotter, renderer.scene, legend=False, colorbar=False)
        np.testing.assert_array_equal(renderer.image(marker=False), img)  # the same frame
        (lw, lh), bottom = overlay_boxes(1600, 1200, renderer.scene.overlay())
    finally:
        renderer.close()
    shape = (bare[..., :3] < 245).any(axis=2)
    assert shape.sum() > 100_000
    assert not shape[:lh, :lw].any() and not shape[1200 - bottom :].any()
    assert not shape[:, :3].any() and not shape[:, -3:].any()
    assert not shape[:3].any()
    # with the check box's choice the marker is drawn
    marked = np.asarray(
        Image.open(window.export_screenshot(tmp_path / "m.png", size=(1600, 1200), marker=True))
    )
    assert _magenta(marked) > 20


def test_the_export_dialog_asks_for_width_and_height(window, spot_path, qtbot, tmp_path):
    from modalviewer.gui import file_dialogs

    _shells_mode_with_a_pick(window, spot_path, qtbot)
    out = tmp_path / "dialog.png"

    def fill():
        dialog = QtWidgets.QApplication.activeModalWidget()
        dialog.path_edit.setText(str(out))
        dialog.width_box.setValue(800)
        dialog.height_box.setValue(500)
        assert not dialog.marker.isChecked()  # a mode: no marker by default
        dialog.accept()

    QtCore.QTimer.singleShot(200, fill)
    file_dialogs.screenshot_dialog(window)
    assert Image.open(out).size == (800, 500)


def test_file_export_animation_writes_a_gif(window, spot_path, qtbot, tmp_path):
    from modalviewer.gui import file_dialogs

    _shells_mode_with_a_pick(window, spot_path, qtbot)
    actions = [a.text().replace("&", "") for a in window.menuBar().actions()[0].menu().actions()]
    assert "Export animation (GIF/MP4)..." in actions
    out = tmp_path / "anim.gif"

    def fill():
        dialog = QtWidgets.QApplication.activeModalWidget()
        dialog.path_edit.setText(str(out))
        dialog.width_box.setValue(240)
        dialog.height_box.setValue(180)
        dialog.frames.setValue(6)
        dialog.accept()

    QtCore.QTimer.singleShot(200, fill)
    file_dialogs.animation_dialog(window)
    with Image.open(out) as image:
        assert (image.n_frames, image.size) == (6, (240, 180))
    assert f"Saved {out}" in window.statusBar().currentMessage()


def _bar_colours(panel: np.ndarray, colors) -> float:
    """The largest deviation (0..255) of the middle row of a continuous colour bar, as
    :func:`modalviewer.scene.overlay.draw_overlay` places it at the bottom of a view
    (``panel``: the view's pixels below its caption), from the gradient through
    ``colors``."""
    from modalviewer.scene.overlay import FONT_PX, MARGIN_PX

    h, w = panel.shape[:2]
    width = min(0.5 * w, 320)
    x0 = 0.5 * (w - width)
    y1 = h - MARGIN_PX - FONT_PX - 0.4 * FONT_PX
    row = int(round(y1 - 0.45 * FONT_PX))
    xs = np.arange(int(x0) + 3, int(x0 + width) - 3)
    t = (xs + 0.5 - x0) / width
    anchors = np.linspace(0, 1, len(colors))
    want = np.column_stack([np.interp(t, anchors, [c[i] for c in colors]) for i in range(3)])
    return float(np.abs(panel[row, xs, :3].astype(float) - 255 * want).max())


def test_a_compare_windows_export_has_a_colour_bar_per_continuous_view(
    window, spot_path, qtbot, tmp_path
):
    from modalviewer.scene.colors import COLORMAPS

    assert window.open_mesh(spot_path)
    for op in ("laplacian", "shells"):
        window.compute(op, k=12, wait=True)
    window.viewer.pick_vertex(1500)
    window.viewer.show_distance("vibration", display="continuous")
    compare = window.open_comparison(["vibration", "hks"])
    qtbot.wait(50)
    out = tmp_path / "compare.png"
    QtCore.QTimer.singleShot(
        200,
        lambda: (
            QtWidgets.QApplication.activeModalWidget().path_edit.setText(str(out)),
            QtWidgets.QApplication.activeModalWidget().accept(),
        ),
    )
    qtbot.keyClick(compare, QtCore.Qt.Key.Key_E, QtCore.Qt.KeyboardModifier.ControlModifier)
    img = np.asarray(Image.open(out))
    heights = [vp.plotter.window_size[1] for vp in compare.viewports]
    widths = [vp.plotter.window_size[0] for vp in compare.viewports]
    assert img.shape[1] == sum(widths) + 4
    x = 0
    for w, h in zip(widths, heights, strict=True):
        panel = img[img.shape[0] - h :, x : x + w]  # below the caption
        assert _bar_colours(panel, COLORMAPS["sequential"]) < 12
        x += w + 4
    # a threshold map: each view's two-swatch legend (the blue swatch) instead
    window.viewer.show_distance("vibration", display="threshold", share=0.2)
    images = grab_views(compare.viewports, compare.scenes)
    for image in images:
        bottom = image[-80:].astype(int)
        blue = (bottom[..., 2] - bottom[..., 0] > 80).sum()
        assert blue > 100, blue


def test_a_session_restores_the_modes_panel_as_it_was(window, spot_path, qtbot, tmp_path):
    """Saved on E_D^N mode 5 with a distance map on screen, the reopened window's Modes
    panel shows E_D^N and mode 5 (it showed the first spectrum computed and mode 0),
    and the distance map, pick, share and display come back."""
    from modalviewer.gui import MainWindow

    assert window.open_mesh(spot_path)
    window.compute("laplacian", k=12, wait=True)
    window.compute("modified_dirichlet", k=12, wait=True)
    window.compute("shells", k=12, wait=True)
    window.show_mode(5, "modified_dirichlet")
    window.viewer.pick_vertex(1500, show=False)
    window.viewer.show_distance("vibration", display="threshold", share=0.15)
    session = window.save_session(tmp_path / "s.json")
    second = MainWindow()
    qtbot.addWidget(second)
    second.show()
    qtbot.waitExposed(second)
    try:
        assert second.open_session(session, wait=True) == []
        panel = second.modes_panel
        assert panel.spectrum_combo.currentData() == "modified_dirichlet"
        assert panel.mode_spin.value() == 5 and panel.mode_slider.value() == 5
        d = second.state.display
        assert (d.kind, d.distance_kind, d.distance_display) == (
            "distance",
            "vibration",
            "threshold",
        )
        assert second.state.picked == 1500
        assert second.state.derived.marked_share() == pytest.approx(0.15, abs=0.01)
        assert second.distances_panel.kind_combo.currentData() == "vibration"
    finally:
        second.close()


def test_file_exports_write_the_file_chosen(window, spot_path, tmp_path, monkeypatch):
    """File > Export field, Export spectrum, Export mode grid and Save session write the
    file chosen in the save dialog and say so in the status bar."""
    import pyvista as pv

    from modalviewer.core.spectrum import load_spectrum
    from modalviewer.gui import file_dialogs

    assert window.open_mesh(spot_path)
    spec = window.compute("laplacian", k=10, wait=True)
    window.show_mode(3)
    chosen = []
    monkeypatch.setattr(
        QtWidgets.QFileDialog, "getSaveFileName", lambda *a, **k: (str(chosen[-1]), "")
    )
    monkeypatch.setattr(QtWidgets.QInputDialog, "getText", lambda *a, **k: ("1-4", True))
    for name, dialog in (
        ("mode.vtp", file_dialogs.field_dialog),
        ("spec.npz", file_dialogs.spectrum_dialog),
        ("grid.png", file_dialogs.mode_grid_dialog),
        ("spot.session.json", file_dialogs.save_session_dialog),
    ):
        chosen.append(tmp_path / name)
        dialog(window)
        assert chosen[-1].is_file(), name
        assert f"Saved {chosen[-1]}" in window.statusBar().currentMessage(), name
    field = pv.read(chosen[0]).point_data
    np.testing.assert_allclose(field[field.keys()[0]], spec.mode(3), atol=1e-6)
    np.testing.assert_allclose(load_spectrum(chosen[1]).eigenvalues, spec.eigenvalues)
    assert Image.open(chosen[2]).size[0] > Image.open(chosen[2]).size[1]  # modes side by side
    assert window.open_session(chosen[3]) == []
