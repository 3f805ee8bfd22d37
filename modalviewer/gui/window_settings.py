"""What the main window remembers between desktop runs (QSettings): layout, view and
compute preferences, recent files, the up axis chosen per file.  Off-screen runs
(tests, ``make run`` without a display) neither read the layout nor write anything."""

from __future__ import annotations

import json
import os
from pathlib import Path

from qtpy import QtCore, QtGui

from ..core.operators import OPERATOR_INFO
from ..viewer.camera import AXES
from ..viewer.state import RENDER_STYLES, SHELL_COLORINGS
from .docks import fit_modes_dock

PREFERENCES = (
    # (key, part of the state, its field, default, type or the values allowed)
    ("view/isolines", "style", "isolines", 12, int),
    ("view/shell_color", "style", "shell_coloring", "deformed", SHELL_COLORINGS),
    ("view/ghost", "style", "ghost", True, bool),
    ("view/style", "style", "render", "paper", RENDER_STYLES),
    ("view/colorbar", "style", "colorbar", True, bool),
    ("view/log_signature", "style", "log_signature", False, bool),
    # the largest displacement of the deformed shape and of the animation
    ("view/mode_amplitude", "animation", "amplitude", 40, int),
    ("view/speed", "animation", "speed", 30, int),
    ("compute/operator", "compute_settings", "operator", "modified_dirichlet", OPERATOR_INFO),
    ("compute/bending", "compute_settings", "bending", 1.0, float),
    ("compute/membrane", "compute_settings", "membrane", 1.0, float),
    ("compute/rescale", "compute_settings", "rescale", False, bool),
    ("compute/coarse", "compute_settings", "coarse", False, bool),
)
"""The preferences remembered; a value not allowed gives the default (an option offered
no longer, a damaged file), never an error at start-up."""


def settings() -> QtCore.QSettings:
    path = os.environ.get("MODALVIEWER_SETTINGS")
    if path:
        return QtCore.QSettings(path, QtCore.QSettings.Format.IniFormat)
    return QtCore.QSettings("modalviewer", "modalviewer")


def headless() -> bool:
    """True on Qt's off-screen or minimal platform (no desktop to remember)."""
    return QtGui.QGuiApplication.platformName() in ("offscreen", "minimal")


def _text(value):
    """A value as stored: on/off as "true" / "false"."""
    return ("true" if value else "false") if isinstance(value, bool) else value


def _read(s, key: str, default, kind):
    value = s.value(key, _text(default))
    if kind is bool:
        return str(value).lower() == "true"
    if isinstance(kind, type):
        return kind(value)
    return str(value) if str(value) in kind else default


def restore(win) -> None:
    s = win.settings
    geometry = s.value("window/geometry") if win.remember_settings else None
    if geometry is None or not win.restoreGeometry(geometry):  # none, or not readable
        win.resize(1280, 820)
    state = s.value("window/state") if win.remember_settings else None
    if state is not None:
        win.restoreState(state)
    else:  # once the window is laid out
        QtCore.QTimer.singleShot(0, win, lambda: fit_modes_dock(win))
    st = win.state
    for key, part, field, default, kind in PREFERENCES:
        setattr(getattr(st, part), field, _read(s, key, default, kind))
    _restore_color_range(st, s)
    rebuild_recent(win)


def _restore_color_range(st, s) -> None:
    """The colour range rule and typed limits as saved; a damaged entry gives the default
    (the automatic range), never an error at start-up."""
    try:
        low, high = (float(x) for x in str(s.value("view/color_limits", "")).split())
        limits = (low, high)
    except ValueError:
        limits = None
    try:  # refused: a rule not offered, limits not low < high, "limits" without them
        st.set_color_range(str(s.value("view/color_range", "auto")), limits)
    except ValueError:
        st.set_color_range("auto")


def save(win) -> None:
    """Remember window layout, view and compute preferences (desktop runs only)."""
    if not win.remember_settings:
        return
    s, st = win.settings, win.state
    s.setValue("window/geometry", win.saveGeometry())
    s.setValue("window/state", win.saveState())
    for key, part, field, _default, _kind in PREFERENCES:
        s.setValue(key, _text(getattr(getattr(st, part), field)))
    s.setValue("view/color_range", st.style.color_range)
    limits = st.style.color_limits
    s.setValue("view/color_limits", "" if limits is None else f"{limits[0]!r} {limits[1]!r}")
    for removed in ("compute/preview", "compute/preview_only"):  # options no longer offered
        s.remove(removed)
    s.sync()


def recent_files(win) -> list[str]:
    value = win.settings.value("files/recent", [])
    if isinstance(value, str):
        value = [value]
    return [str(v) for v in (value or [])]


def rebuild_recent(win) -> None:
    win.recent_menu.clear()
    for path in recent_files(win):
        action = win.recent_menu.addAction(path)
        action.triggered.connect(lambda _=False, p=path: win.open_mesh(p))
    win.recent_menu.setEnabled(bool(recent_files(win)))


def remember_file(win, path: Path) -> None:
    if not win.remember_settings:
        return
    recent = [str(path)] + [p for p in recent_files(win) if p != str(path)]
    win.settings.setValue("files/recent", recent[:10])
    win.settings.setValue("files/last_dir", str(path.parent))
    rebuild_recent(win)


UP_AXES_KEY = "files/up_axes"
"""QSettings key of the up axes chosen per file: a JSON object, path -> axis."""
UP_AXES_KEPT = 200  # files whose up axis is remembered (the most recently chosen)


def _up_axes(win) -> dict[str, str]:
    try:
        value = json.loads(str(win.settings.value(UP_AXES_KEY, "{}")))
    except ValueError:
        return {}
    return {str(k): str(v) for k, v in value.items()} if isinstance(value, dict) else {}


def choose_up_axis(win, axis: str | None) -> None:
    """View > Up axis: set the state's up axis (the view turns to the canonical one for
    it) and remember it (None: automatic, forgotten) for the file shown."""
    win.state.up_axis = axis
    path = win.state.mesh_path
    if path is None or not win.remember_settings:
        return
    key = str(Path(path).resolve())
    axes = {k: v for k, v in _up_axes(win).items() if k != key}
    if win.state.up_axis is not None:
        axes[key] = win.state.up_axis
    kept = dict(list(axes.items())[-UP_AXES_KEPT:])
    win.settings.setValue(UP_AXES_KEY, json.dumps(kept))


def restore_up_axis(win) -> None:
    """A newly loaded file gets the up axis chosen for it before, if any."""
    path = win.state.mesh_path
    if path is None or win.state.mesh is None or not win.remember_settings:
        return
    axis = _up_axes(win).get(str(Path(path).resolve()))
    if axis in AXES:
        win.state.up_axis = axis
