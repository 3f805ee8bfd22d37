"""Figures from the real window: the export dialog's width and height, the shape clear of
the legend whatever the window's size, no pick marker on a mode's picture, File > Export
animation."""

import numpy as np
import pytest
from PIL import Image
from qtpy import QtCore, QtWidgets

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
    window.state.set_colorbar(True)
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
