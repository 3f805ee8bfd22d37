"""The main window's docks: Compute (with the computations list), Modes (with the
animation) and Distances and signatures, each scrolling inside a dock."""

from __future__ import annotations

from qtpy import QtCore, QtWidgets

DOCK_WIDTH = 340
"""Widest a dock gets, in pixels."""


def build_docks(win) -> None:
    """Put ``win``'s panels (``compute_panel``, ``jobs_panel``, ``modes_panel``,
    ``animation_panel``, ``distances_panel``) into its docks."""
    area = QtCore.Qt.DockWidgetArea
    compute = QtWidgets.QWidget()
    lay = QtWidgets.QVBoxLayout(compute)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.addWidget(win.compute_panel)
    lay.addWidget(QtWidgets.QLabel("<b>Computations</b>"))
    lay.addWidget(win.jobs_panel)
    lay.addStretch(1)
    add_dock(win, "Compute", compute, area.LeftDockWidgetArea)
    modes = QtWidgets.QWidget()
    lay = QtWidgets.QVBoxLayout(modes)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.addWidget(win.modes_panel)
    # one panel's bottom margin between the two, not two margins
    margins = win.animation_panel.layout().contentsMargins()
    margins.setTop(0)
    win.animation_panel.layout().setContentsMargins(margins)
    lay.addWidget(win.animation_panel)
    win.modes_dock = add_dock(win, "Modes", modes, area.RightDockWidgetArea)
    win.distances_dock = add_dock(
        win, "Distances and signatures", win.distances_panel, area.RightDockWidgetArea
    )


MODES_NOTE_LINES = 4
"""Lines the Modes dock keeps for the eigenvalue line's note (a coarse-to-fine
spectrum's, after the eigenvalue or after the two-line "Not shown (M shows it): ... on
screen") beyond the one line it has at the start."""


def fit_modes_dock(win) -> None:
    """Give the Modes dock the height its controls need (the eigenvalue note's
    :data:`MODES_NOTE_LINES` included) and the Distances dock below it the rest (it
    scrolls): an even split hides the Modes dock's last rows at the default window size.
    For a first start; a remembered layout is kept."""
    modes, distances = win.modes_dock, win.distances_dock
    total = modes.height() + distances.height()
    content = modes.widget().widget()
    note = MODES_NOTE_LINES * win.modes_panel.eigen_label.fontMetrics().lineSpacing()
    frame = modes.height() - modes.widget().viewport().height()
    need = content.sizeHint().height() + note + frame
    rest = max(total - need, distances.minimumSizeHint().height())
    win.resizeDocks([modes, distances], [total - rest, rest], QtCore.Qt.Orientation.Vertical)


def add_dock(win, title: str, widget: QtWidgets.QWidget, area) -> QtWidgets.QDockWidget:
    """A dock titled ``title`` holding ``widget`` in a vertical scroll area, wide enough
    for the widget's contents (no sideways scrolling; labels wrap)."""
    dock = QtWidgets.QDockWidget(
        title, win, maximumWidth=DOCK_WIDTH, objectName=title.replace(" ", "_")
    )
    off = QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff
    scroll = QtWidgets.QScrollArea(widgetResizable=True, horizontalScrollBarPolicy=off)
    scroll.setWidget(widget)
    needed = widget.minimumSizeHint().width() + scroll.verticalScrollBar().sizeHint().width()
    scroll.setMinimumWidth(min(DOCK_WIDTH, needed + 4))
    dock.setWidget(scroll)
    win.addDockWidget(area, dock)
    return dock
