"""What the main window remembers between desktop runs (QSettings): layout, view and
compute preferences, recent files.  Off-screen runs (tests, ``make run`` without a
display) neither read the layout nor write anything."""

from __future__ import annotations

import os
from pathlib import Path

from qtpy import QtCore, QtGui

from ..core.operators import OPERATOR_INFO
from ..viewer.state import COLOR_RANGES, RENDER_STYLES, SHELL_COLORINGS
from .docks import fit_modes_dock


def settings() -> QtCore.QSettings:
    path = os.environ.get("MODALVIEWER_SETTINGS")
    if path:
        return QtCore.QSettings(path, QtCore.QSettings.Format.IniFormat)
    return QtCore.QSettings("modalviewer", "modalviewer")


def headless() -> bool:
    """True on Qt's off-screen or minimal platform (no desktop to remember)."""
    return QtGui.QGuiApplication.platformName() in ("offscreen", "minimal")


def _flag(settings, key: str, default: bool) -> bool:
    """A remembered on/off setting (stored as "true" / "false")."""
    return str(settings.value(key, _flag_text(default))).lower() == "true"


def _flag_text(on: bool) -> str:
    return "true" if on else "false"


def restore(win) -> None:
    s = win.settings
    geometry = s.value("window/geometry") if win.remember_settings else None
    if geometry is not None:
        win.restoreGeometry(geometry)
    else:
        win.resize(1280, 820)
    state = s.value("window/state") if win.remember_settings else None
    if state is not None:
        win.restoreState(state)
    else:  # once the window is laid out
        QtCore.QTimer.singleShot(0, win, lambda: fit_modes_dock(win))
    st = win.state
    st.style.isolines = int(s.value("view/isolines", 12))
    coloring = str(s.value("view/shell_color", "deformed"))  # a former "auto": deformed
    st.style.shell_coloring = coloring if coloring in SHELL_COLORINGS else "deformed"
    st.style.ghost = _flag(s, "view/ghost", True)
    style = str(s.value("view/style", "paper"))
    st.style.render = style if style in RENDER_STYLES else "paper"
    st.style.colorbar = _flag(s, "view/colorbar", True)
    _restore_color_range(st, s)
    st.style.log_signature = _flag(s, "view/log_signature", False)
    # the largest displacement of the deformed shape and of the animation
    st.animation.amplitude = int(s.value("view/mode_amplitude", 40))
    st.animation.speed = int(s.value("view/speed", 30))
    c, operator = st.compute_settings, str(s.value("compute/operator", "modified_dirichlet"))
    c.operator = operator if operator in OPERATOR_INFO else "modified_dirichlet"
    c.bending = float(s.value("compute/bending", 1.0))
    c.membrane = float(s.value("compute/membrane", 1.0))
    c.rescale = _flag(s, "compute/rescale", False)
    c.coarse = _flag(s, "compute/coarse", False)
    rebuild_recent(win)


def _restore_color_range(st, s) -> None:
    """The colour range rule and typed limits as saved; a damaged entry gives the default
    (the automatic range), never an error at start-up."""
    rule = str(s.value("view/color_range", "auto"))
    try:
        low, high = (float(x) for x in str(s.value("view/color_limits", "")).split())
        limits = (low, high)
    except ValueError:
        limits = None
    if rule not in COLOR_RANGES or (rule == "limits" and limits is None):
        rule = "auto"
    try:
        st.set_color_range(rule, limits)
    except ValueError:
        st.set_color_range("auto")


def save(win) -> None:
    """Remember window layout, view and compute preferences (desktop runs only)."""
    if not win.remember_settings:
        return
    s, st = win.settings, win.state
    s.setValue("window/geometry", win.saveGeometry())
    s.setValue("window/state", win.saveState())
    s.setValue("view/isolines", st.style.isolines)
    s.setValue("view/mode_amplitude", st.animation.amplitude)
    s.setValue("view/speed", st.animation.speed)
    s.setValue("view/shell_color", st.style.shell_coloring)
    s.setValue("view/style", st.style.render)
    s.setValue("view/colorbar", _flag_text(st.style.colorbar))
    s.setValue("view/ghost", _flag_text(st.style.ghost))
    s.setValue("view/color_range", st.style.color_range)
    limits = st.style.color_limits
    s.setValue("view/color_limits", "" if limits is None else f"{limits[0]!r} {limits[1]!r}")
    s.setValue("view/log_signature", _flag_text(st.style.log_signature))
    c = st.compute_settings
    s.setValue("compute/operator", c.operator)
    s.setValue("compute/bending", c.bending)
    s.setValue("compute/membrane", c.membrane)
    s.setValue("compute/rescale", _flag_text(c.rescale))
    s.setValue("compute/coarse", _flag_text(c.coarse))
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
    import json

    try:
        value = json.loads(str(win.settings.value(UP_AXES_KEY, "{}")))
    except ValueError:
        return {}
    return {str(k): str(v) for k, v in value.items()} if isinstance(value, dict) else {}


def remembered_up_axis(win, path) -> str | None:
    """The up axis chosen for the file ``path`` (View > Up axis), or None: automatic."""
    from ..viewer.camera import AXES

    if path is None or not win.remember_settings:
        return None
    axis = _up_axes(win).get(str(Path(path).resolve()))
    return axis if axis in AXES else None


def remember_up_axis(win, path, axis: str | None) -> None:
    """Remember ``axis`` (None: automatic, forgotten) for the file ``path``."""
    import json

    if path is None or not win.remember_settings:
        return
    key = str(Path(path).resolve())
    axes = {k: v for k, v in _up_axes(win).items() if k != key}
    if axis is not None:
        axes[key] = axis
    kept = dict(list(axes.items())[-UP_AXES_KEPT:])
    win.settings.setValue(UP_AXES_KEY, json.dumps(kept))


def choose_up_axis(win, axis: str | None) -> None:
    """View > Up axis: set the state's up axis (the view turns to the canonical one for
    it) and remember it for the file shown."""
    win.state.up_axis = axis
    remember_up_axis(win, win.state.mesh_path, win.state.up_axis)


def restore_up_axis(win) -> None:
    """A newly loaded file gets the up axis chosen for it before, if any."""
    axis = remembered_up_axis(win, win.state.mesh_path)
    if axis is not None and win.state.mesh is not None:
        win.state.up_axis = axis
