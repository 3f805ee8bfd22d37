"""The main window's menus and the Help texts (actions call the window's public methods
and the file dialogs; no state of their own)."""

from __future__ import annotations

import html

from qtpy import QtCore, QtGui, QtWidgets

from ..repair import REPAIRS
from . import file_dialogs
from .collection_dialog import open_collection_dialog


def _action(win, menu, text, slot, shortcut=None, tip=None) -> QtGui.QAction:
    key = QtGui.QKeySequence(shortcut or "")
    action = QtGui.QAction(text, win, shortcut=key, statusTip=tip or "", triggered=slot)
    menu.addAction(action)
    return action


class ShortcutsThroughNumberFields(QtCore.QObject):
    """Lets the shortcuts of ``actions`` (Ctrl+Left/Right: previous / next mode) reach
    them from every number field (spin box) of ``win``, which would otherwise take the
    keys to move its cursor by words: the override request is left unaccepted, so the
    window's shortcut runs."""

    def __init__(self, actions, win):
        super().__init__(win)
        self.keys = {action.shortcut().toString() for action in actions}
        for box in win.findChildren(QtWidgets.QAbstractSpinBox):
            box.installEventFilter(self)
            if box.lineEdit() is not None:
                box.lineEdit().installEventFilter(self)

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 (Qt override)
        return (
            event.type() == QtCore.QEvent.Type.ShortcutOverride
            and QtGui.QKeySequence(event.keyCombination()).toString() in self.keys
        )


def build_menus(win) -> None:
    bar = win.menuBar()
    _file_menu(win, bar.addMenu("&File"))
    m = bar.addMenu("&Mesh")
    for name, label in REPAIRS.items():
        _action(win, m, label + "...", lambda _=False, n=name: win.repair_mesh(n, wait=False))
    m = bar.addMenu("&Compute")
    _action(win, m, "&Compute spectrum", lambda: win.compute(wait=False), "Ctrl+R")
    _action(win, m, "C&ancel running computation", win.cancel_computation, "Esc")
    _action(win, m, "Cancel &all computations", win.cancel_all, "Ctrl+Shift+Esc")
    _view_menu(win, bar.addMenu("&View"))
    m = bar.addMenu("&Help")
    _action(win, m, "&Controls", lambda: controls(win))
    _action(win, m, "&About", lambda: about(win))


_SEPARATOR = (None, None, None, None)
PAIR_TIP = "Open mesh B beside this mesh: a click on one shows the similar points on the other"
COLLECTION_TIP = (
    "A store of 'modalviewer batch': its shapes nearest to this mesh; one opens beside it"
)
ANIMATION_TIP = "One period of the mode shown, vibrating as on screen"
GRID_TIP = "Several modes side by side in one picture, one camera, one colour bar"


def _file_menu(win, m) -> None:
    d = file_dialogs
    _action(win, m, "&Open mesh...", lambda: d.open_mesh_dialog(win), "Ctrl+O")
    win.recent_menu = m.addMenu("Open &recent")
    for text, slot, key, tip in (
        ("Open &second mesh (shape pair)...", d.open_second_mesh_dialog, "Ctrl+Shift+B", PAIR_TIP),
        ("Open co&llection...", open_collection_dialog, None, COLLECTION_TIP),
        _SEPARATOR,
        ("Open s&ession...", d.open_session_dialog, "Ctrl+Shift+O", None),
        ("Save se&ssion...", d.save_session_dialog, "Ctrl+S", None),
        _SEPARATOR,
        ("Export &screenshot...", d.screenshot_dialog, "Ctrl+E", None),
        ("Export &animation (GIF/MP4)...", d.animation_dialog, None, ANIMATION_TIP),
        ("Export mode &grid...", d.mode_grid_dialog, None, GRID_TIP),
        ("Export per-vertex &field (PLY/VTP)...", d.field_dialog, "Ctrl+Shift+E", None),
        ("Export s&pectrum (.npz)...", d.spectrum_dialog, "Ctrl+Shift+S", None),
        _SEPARATOR,
    ):
        if text is None:
            m.addSeparator()
        else:
            _action(win, m, text, lambda _=False, f=slot: f(win), key, tip)
    win.clear_cache_action = _action(
        win, m, "Clear spectrum &cache...", lambda: d.clear_cache_dialog(win)
    )
    m.aboutToShow.connect(lambda: d.update_cache_label(win))
    m.addSeparator()
    _action(win, m, "&Quit", win.close, "Ctrl+Q")


STYLE_TOGGLES = (
    # (attribute of the window, text, key, style field, its value when on, when off)
    ("colorbar_action", "Colour &bar and legend", "B", "colorbar", True, False),
    ("shaded_action", "S&haded look (light kit, greyer)", "Shift+S", "render", "shaded", "paper"),
    ("ghost_action", "Rest shape &ghost behind deformed modes", "G", "ghost", True, False),
)
OPERATORS_COMPARED = ["laplacian", "modified_dirichlet", "shells_normal"]
COMPARISONS = (  # View menu: (text, key, what is compared)
    ("Compare &operators (Laplacian, E_D^N, shells normal)...", "Ctrl+1", OPERATORS_COMPARED),
    ("Compare d&istances (vibration, heat kernel)...", "Ctrl+2", ["vibration", "hks"]),
)

AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
CAMERA_PRESETS = (*((a, f"From {a.upper()}") for a in AXES), ("isometric", "Isometric"))


def _radio(win, menu, items, choose, current, event) -> dict:
    """Checkable items (value, label) of ``menu`` calling ``choose(value)``, one checked
    at a time: the one of ``current()``, now and on ``event``; returns value -> action."""
    group = QtGui.QActionGroup(menu)
    actions = {}
    for value, label in items:
        actions[value] = _action(win, menu, label, lambda _=False, v=value: choose(v))
        actions[value].setCheckable(True)
        group.addAction(actions[value])
    follow = lambda *_: actions[current()].setChecked(True)  # noqa: E731
    follow()
    event.connect(follow)
    return actions


def _view_menu(win, m) -> None:
    steps = [
        _action(win, m, "&Next mode", lambda: win.step_mode(+1), "Ctrl+Right"),
        _action(win, m, "&Previous mode", lambda: win.step_mode(-1), "Ctrl+Left"),
    ]
    ShortcutsThroughNumberFields(steps, win)
    _action(win, m, "Play / pause animation", win.toggle_animation, "P")
    _action(win, m, "Show &mode", win.viewer.show_current_mode, "M")
    _action(win, m, "Show &distance", lambda: win.show_distance(), "D")
    _action(win, m, "Show &curvature sqrt(k1^2 + k2^2)", win.show_curvature, "C")
    for attribute, text, key, field, on_value, off_value in STYLE_TOGGLES:
        values = (off_value, on_value)
        slot = lambda on, f=field, v=values: setattr(win.state.style, f, v[bool(on)])  # noqa: E731
        action = _action(win, m, text, slot, key)
        action.setCheckable(True)

        def follow(a=action, f=field, v=on_value) -> None:
            a.setChecked(getattr(win.state.style, f) == v)

        follow()
        win.state.events.style.connect(follow)
        setattr(win, attribute, action)
    win.color_range_actions = _radio(
        win,
        m.addMenu("Colour &range"),
        COLOR_RANGE_ITEMS,
        lambda rule: ask_color_limits(win) if rule == "limits" else win.state.set_color_range(rule),
        lambda: win.state.style.color_range,
        win.state.events.style,
    )
    panels = m.addMenu("&Panels")
    for dock in win.findChildren(QtWidgets.QDockWidget):
        panels.addAction(dock.toggleViewAction())  # a closed panel comes back from here
    _action(win, m, "&Reset camera", lambda: win.scene_view.drawing.reset_camera(), "R")
    views = m.addMenu("Camera &presets")
    for i, (name, label) in enumerate(CAMERA_PRESETS):
        slot = lambda _=False, n=name: win.scene_view.drawing.reset_camera(n)  # noqa: E731
        _action(win, views, label, slot, f"Alt+{i + 1}")
    _up_axis_menu(win, m)
    m.addSeparator()
    for text, key, items in COMPARISONS:
        slot = lambda _=False, i=items: win.open_comparison(i, wait=False)  # noqa: E731
        _action(win, m, text, slot, key)


COLOR_RANGE_ITEMS = (
    ("auto", "&Automatic (spread or robust for distances, signatures, curvature)"),
    ("symmetric", "&Symmetric: the largest value"),
    ("robust", "&Robust: 99th percentile by area, beyond it clipped"),
    ("spread", "Spread by &area: each tenth of the colours a tenth of the surface"),
    ("limits", "Typed &limits..."),
)


def ask_color_limits(win) -> None:
    """Ask for the colour limits ("low high"), starting from the range on screen."""
    st = win.state
    field = st.derived.field()
    lo, hi = st.style.color_limits or (field.clim if field and field.clim else (0.0, 1.0))
    text, ok = QtWidgets.QInputDialog.getText(
        win, "Colour limits", "Low and high value:", text=f"{lo:.6g} {hi:.6g}"
    )
    if ok:
        try:
            low, high = (float(x) for x in text.replace(",", " ").split())
            st.set_color_range("limits", (low, high))
        except ValueError:
            QtWidgets.QMessageBox.warning(win, "Colour limits", "Type two numbers, low < high.")
    win.color_range_actions[st.style.color_range].setChecked(True)


def about(win) -> None:
    from .. import __version__

    QtWidgets.QMessageBox.about(
        win,
        "About modalviewer",
        f"modalviewer {__version__}: modal shape analysis beyond the Laplacian.\n\n"
        "Laplacian, modified Dirichlet energy E_D^N and Discrete Shells vibration "
        "modes; heat kernel, feature and vibration signatures and distances.",
    )


def controls(win) -> None:
    rich = QtCore.Qt.TextFormat.RichText  # one item per line, no wrapping
    text = "<pre>" + html.escape(CONTROLS) + "</pre>"
    box = QtWidgets.QMessageBox(win, windowTitle="Controls", textFormat=rich, text=text)
    box.exec()


CONTROLS = """Mouse
  Left drag             rotate
  Right drag, wheel     zoom
  Middle drag           pan
  Left click            pick a vertex and show its distance map

Keys in the 3D view (click it first)
  Left / Right          previous / next mode
  Space                 play / pause the vibration

Everywhere (the single letters not while typing in a field)
  Ctrl+Left / Right     previous / next mode
  P                     play / pause
  M / D / C             show the mode / the distance / the curvature
  B                     colour bar and legend on or off
  Shift+S               shaded look on or off
  G                     rest shape ghost behind a deformed 3D mode on or off
  R                     canonical view
  Alt+1 .. Alt+6        view from +X, -X, +Y, -Y, +Z, -Z
  Alt+7                 isometric view
  Ctrl+R                compute the spectrum
  Esc                   cancel the running computation
  Ctrl+1 / Ctrl+2       compare operators / distances
                        (in that window: Left / Right, Esc or Ctrl+W closes)
  Ctrl+Shift+B          open a second mesh beside this one
                        (or drop a file on the right half of the window)
  Ctrl+O / Ctrl+E       open a mesh / export a screenshot
  Ctrl+S / Ctrl+Shift+O save / open a session
  Ctrl+Q                quit"""


def _up_axis_menu(win, menu) -> None:
    """View > Up axis: Automatic (detected +Z where confident, else +Y) or an axis,
    remembered per file; R returns to the canonical view for it."""
    from . import window_settings

    choose = lambda axis: window_settings.choose_up_axis(win, axis)  # noqa: E731
    items = ((None, "&Automatic"), *((a, a.upper()) for a in AXES))
    state = win.state
    up = menu.addMenu("&Up axis")
    actions = _radio(win, up, items, choose, lambda: state.up_axis, state.events.up_axis)
    win.up_axis_actions = actions

    def update() -> None:
        detected = state.derived.up_axis() if state.mesh is not None else None
        shown = state.up_axis is None and detected
        actions[None].setText(f"&Automatic ({detected.upper()})" if shown else "&Automatic")
        actions[state.up_axis].setChecked(True)

    state.events.mesh.connect(lambda: window_settings.restore_up_axis(win))
    state.events.mesh.connect(update)  # after the restore: the new mesh's detected axis
    state.events.up_axis.connect(update)
    update()
