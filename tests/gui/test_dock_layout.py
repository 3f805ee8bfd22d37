"""How the docks lay their panels out: wrapped labels as high as their text, whole plot
titles, every control of the Modes dock in view at the default window size."""

import pytest

pytestmark = pytest.mark.gui


def _settle(qtbot, window):
    """Run the docks' posted layout requests (those a layout posts while it runs too),
    however long the event loop took to get to them on a loaded machine."""
    from qtpy import QtCore, QtWidgets

    for _ in range(4):
        qtbot.wait(20)
        QtWidgets.QApplication.sendPostedEvents(None, QtCore.QEvent.Type.LayoutRequest)
    window.repaint()


def test_eigenvalue_line_sits_on_top_of_the_spectrum_plot(window, spot_path, qtbot):
    """After a two-line "Not shown" note the eigenvalue is one line again, the label
    one line high and the plot right below it (no empty band around the line)."""
    assert window.open_mesh(spot_path)
    window.compute("laplacian", k=10, wait=True)
    panel = window.modes_panel
    label, plot = panel.eigen_label, panel.spectrum_plot
    window.state.set_display(distance_kind="hks")
    window.pick_vertex(300)
    window.state.set_display(kind="distance", distance_display="threshold")
    _settle(qtbot, window)
    assert panel.eigen_label.text().startswith("Not shown")
    line = label.fontMetrics().lineSpacing()
    assert label.height() >= 2 * line  # the note wraps in the dock
    window.show_mode(3)
    _settle(qtbot, window)
    assert label.text().startswith("lambda_3 = ")
    assert "\n" not in label.text()
    assert label.height() <= line + 2, (label.height(), line)
    spacing = panel.layout().spacing()
    gap = plot.geometry().top() - label.geometry().bottom() - 1
    assert 0 <= gap <= spacing + 1, (gap, spacing)


def test_a_one_line_threshold_text_is_one_line_high(window, spot_path, qtbot):
    """The threshold's two-line hint gives way to a one-line value: the label (a form
    row) is one line high, not the line centred in two."""
    assert window.open_mesh(spot_path)
    window.compute("laplacian", k=10, wait=True)
    label = window.distances_panel.threshold_label
    line = label.fontMetrics().lineSpacing()
    window.state.set_display(distance_kind="hks")
    window.pick_vertex(300)
    _settle(qtbot, window)
    assert "% of surface" in label.text() and "\n" not in label.text()
    assert label.fontMetrics().horizontalAdvance(label.text()) < label.width()
    assert label.height() <= line + 2, (label.height(), line)


def test_the_whole_modes_dock_shows_at_the_default_window_size(qtbot, spot_path):
    """Seen under Xvfb: the Speed slider lay below the Modes dock's visible part at the
    default window size (the right docks split the height evenly). With a mode shown,
    every control of the dock, Speed included, is inside the dock's scroll area without
    scrolling (the Distances dock below takes the rest and scrolls)."""
    from qtpy import QtCore, QtWidgets

    from modalviewer.gui import MainWindow
    from modalviewer.gui.docks import MODES_NOTE_LINES

    win = MainWindow()
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    assert (win.width(), win.height()) == (1280, 820)  # the size of a first start
    _settle(qtbot, win)
    # the first start sizes the Modes dock to its controls and a note, not half the
    # height (the offscreen platform's fonts fit either way; Xvfb's did not)
    dock = win.modes_dock
    line = win.modes_panel.eigen_label.fontMetrics().lineSpacing()
    frame = dock.height() - dock.widget().viewport().height()
    need = dock.widget().widget().sizeHint().height() + MODES_NOTE_LINES * line + frame
    assert abs(dock.height() - need) <= 8, (dock.height(), need)
    assert win.open_mesh(spot_path)
    win.compute("laplacian", k=10, wait=True)
    _settle(qtbot, win)
    modes, animation = win.modes_panel, win.animation_panel
    scroll = animation.parentWidget()
    while not isinstance(scroll, QtWidgets.QScrollArea):
        scroll = scroll.parentWidget()
    assert scroll.widget().isAncestorOf(modes)
    viewport = scroll.viewport()
    assert scroll.verticalScrollBar().value() == 0
    assert scroll.verticalScrollBar().maximum() == 0  # nothing of the dock out of view
    assert win.distances_dock.height() >= win.distances_dock.minimumSizeHint().height()
    shown = viewport.rect()
    for widget in (
        modes.spectrum_combo,
        modes.mode_spin,
        modes.eigen_label,
        modes.spectrum_plot,
        modes.color_combo,
        modes.iso_spin,
        animation.amp_slider,
        animation.speed_slider,
        animation.play_button,
    ):
        top_left = widget.mapTo(viewport, QtCore.QPoint(0, 0))
        where = QtCore.QRect(top_left, widget.size())
        assert shown.contains(where), (widget, where, shown)
    assert animation.speed_slider.width() >= 100
    label = modes.eigen_label
    # found under Xvfb: with a distance map on screen the "Not shown" note pushed
    # Amplitude, Speed and Play out of view
    win.state.set_display(distance_kind="hks")
    win.pick_vertex(300)
    win.state.set_display(kind="distance")
    _settle(qtbot, win)
    assert label.text().startswith("Not shown")
    # the note keeps to the lines the dock keeps for it (the offscreen platform's
    # narrower font leaves room either way; Xvfb's did not)
    line = label.fontMetrics().lineSpacing()
    assert label.height() <= (1 + MODES_NOTE_LINES) * line + 2, (label.height(), line)
    assert scroll.verticalScrollBar().maximum() == 0
    for widget in (animation.amp_slider, animation.speed_slider, animation.play_button):
        top_left = widget.mapTo(viewport, QtCore.QPoint(0, 0))
        assert shown.contains(QtCore.QRect(top_left, widget.size())), widget
    win.close()
