"""File dialogs of the main window: each asks for a path or a confirmation, then calls
the window's scripting method (``open_mesh``, ``export_screenshot``, ``save_session``,
...), which does the work and reports errors."""

from __future__ import annotations

import os
from pathlib import Path

from qtpy import QtWidgets

from ..core.operators import operator_info
from ..core.spectrum import save_spectrum
from ..io import SUPPORTED_EXTENSIONS
from .dialogs import NO_MESH_A, AnimationDialog, ScreenshotDialog, ask
from .paths import ASSETS, SCREENSHOTS


def _mesh_folder(win) -> Path:
    """Where files about the open mesh go by default: its folder if writable, else the
    screenshots folder of a source checkout, else the home folder."""
    path = win.state.mesh_path
    if path is not None and os.access(Path(path).resolve().parent, os.W_OK):
        return Path(path).resolve().parent
    if os.access(SCREENSHOTS, os.W_OK):
        return SCREENSHOTS
    return Path.home()


def _picture_folder(win) -> str:
    """Where the last picture went, else the mesh's folder (:func:`_mesh_folder`)."""
    return str(win.settings.value("files/screenshot_dir", str(_mesh_folder(win))))


def _save(win, what: str, write, say=None, **remember) -> Path | None:
    """Run ``write()`` and say the file it wrote (by ``say``, default the status bar), or
    that the ``what`` could not be saved (by ``say``, default an error message); then
    remember the settings ``remember`` (key: value) where the window remembers them."""
    try:
        out = write()
    except (OSError, ValueError) as exc:
        (say or win.show_error)(f"Could not save the {what}: {exc}")
        return None
    if win.remember_settings:
        for key, value in remember.items():
            win.settings.setValue(f"files/{key}", value)
    (say or (lambda text: win.statusBar().showMessage(text, 8000)))(f"Saved {out}")
    return out


def _mesh_file(win, title: str, start) -> str:
    """A mesh file chosen by the user ("" if none), starting in the last folder opened."""
    start = str(win.settings.value("files/last_dir", str(start)))
    patterns = " ".join(f"*{e}" for e in SUPPORTED_EXTENSIONS)
    filters = f"Meshes ({patterns});;All files (*)"
    return QtWidgets.QFileDialog.getOpenFileName(win, title, start, filters)[0]


def open_mesh_dialog(win) -> None:
    path = _mesh_file(win, "Open mesh", ASSETS)
    if path:
        win.open_mesh(path)


def open_second_mesh_dialog(win) -> None:
    """File > Open second mesh...: choose mesh B of the shape pair."""
    if win.state.mesh is None:
        win.show_error(NO_MESH_A)
        return
    path = _mesh_file(win, "Open second mesh (B)", Path.cwd())
    if path:
        win.open_second_mesh(path, wait=False)


def _saved_size(win, key: str, default) -> tuple[int, int]:
    """The picture size last asked for under ``key`` in the settings, else ``default``."""
    try:
        w, h = (int(x) for x in str(win.settings.value(key, "")).split("x"))
        return (w, h)
    except ValueError:
        return tuple(int(x) for x in default)


def screenshot_dialog(win) -> None:
    start = _picture_folder(win)
    size = _saved_size(win, "files/screenshot_size", (1024, 768))
    marker = win.viewer.marker_shown()
    dialog = ScreenshotDialog(win, start, win.state.style.colorbar, size, marker)
    if dialog.exec() != QtWidgets.QDialog.DialogCode.Accepted:
        return
    path, scale, transparent, colorbar, size, marker = dialog.values()
    _save(
        win,
        "screenshot",
        lambda: win.export_screenshot(path, scale, transparent, colorbar, size, marker),
        screenshot_dir=str(Path(path).parent),
        screenshot_size=f"{size[0]}x{size[1]}",
    )


def animation_dialog(win) -> None:
    """File > Export animation: one period of the mode shown (a mode must be shown)."""
    from ..scene.animation import ANIMATION_SIZE, DEFAULT_FPS, period_frames

    d = win.state.display
    if d.kind != "mode" or win.state.spectrum(d.operator) is None:
        win.show_error("Show a vibration mode first: an animation shows a mode vibrating.")
        return
    start = _picture_folder(win)
    size = _saved_size(win, "files/animation_size", ANIMATION_SIZE)
    frames = period_frames(win.state.animation.speed, DEFAULT_FPS)
    dialog = AnimationDialog(win, start, size, frames, DEFAULT_FPS)
    if dialog.exec() != QtWidgets.QDialog.DialogCode.Accepted:
        return
    path, size, frames, fps = dialog.values()
    win.statusBar().showMessage(f"Writing {Path(path).name} ({frames} frames)...")
    QtWidgets.QApplication.processEvents()
    _save(
        win,
        "animation",
        lambda: win.viewer.export_animation(path, frames=frames, fps=fps, size=size),
        screenshot_dir=str(Path(path).parent),
        animation_size=f"{size[0]}x{size[1]}",
    )


def window_screenshot_dialog(window, name: str, title: str) -> None:
    """Export a window of several views (shape pair, comparison) as one picture with the
    main window's dialog (file, size multiplier, transparent background; the views at
    their on-screen size with legends and colour bars), starting where the main window's
    screenshots go; the result is said in the window's status line, or the main one's."""
    win = window.main
    start = _picture_folder(win)
    dialog = ScreenshotDialog(window, start, size=None, marker=None)
    dialog.setWindowTitle(title)
    dialog.path_edit.setText(str(Path(start) / name))
    dialog.colorbar.hide()  # the views' legends and colour bars are part of the picture
    if dialog.exec() != QtWidgets.QDialog.DialogCode.Accepted:
        return
    path, scale, transparent, _, _, _ = dialog.values()
    status = getattr(window, "status", None)
    say = status.setText if status is not None else lambda t: win.statusBar().showMessage(t, 8000)
    write = lambda: window.export_screenshot(path, scale, transparent)  # noqa: E731
    _save(win, "screenshot", write, say, screenshot_dir=str(Path(path).parent))


def _save_as(win, what: str, title: str, start, filters: str, write) -> None:
    """Ask where to save the ``what`` (starting at ``start``), then :func:`_save` it with
    ``write(path)``."""
    path, _ = QtWidgets.QFileDialog.getSaveFileName(win, title, str(start), filters)
    if path:
        _save(win, what, lambda: write(path))


def field_dialog(win) -> None:
    if win.scene is not None:
        start = _mesh_folder(win) / "field.vtp"
        filters = "VTK PolyData (*.vtp);;PLY (*.ply)"
        _save_as(win, "field", "Export per-vertex field", start, filters, win.export_field)


def spectrum_dialog(win) -> None:
    spec = win.viewer.spectrum_shown()
    if spec is None:
        win.show_error("Compute a spectrum first.")
        return
    folder = Path(win.state.mesh_path).parent if win.state.mesh_path else Path.cwd()
    title = f"Export spectrum: {spec.operator_info.label}"
    write = lambda path: save_spectrum(spec, path) or path  # noqa: E731
    _save_as(win, "spectrum", title, folder / f"{spec.operator}.npz", "NumPy (*.npz)", write)


def update_cache_label(win) -> None:
    size = win.cache.size_bytes()
    win.clear_cache_action.setText(f"Clear spectrum &cache ({size / 2**20:.0f} MB)...")


def clear_cache_dialog(win) -> None:
    size = win.cache.size_bytes()
    limit = getattr(win.cache, "max_bytes", 0)
    question = (
        f"The spectrum cache in {win.cache.directory} holds {size / 2**20:.0f} MB "
        f"(limit {limit / 2**20:.0f} MB; the least recently used spectra go first). "
        "Delete all cached spectra? Spectra on screen stay."
    )
    if ask(win, "Clear cache", question):
        win.clear_cache()


def save_session_dialog(win) -> None:
    if win.state.mesh is None:
        win.show_error("Open a mesh first.")
        return
    start = _mesh_folder(win) / f"{Path(win.state.mesh_path or 'mesh').stem}.session.json"
    _save_as(win, "session", "Save session", start, "Session (*.json)", win.save_session)


def open_session_dialog(win) -> None:
    path, _ = QtWidgets.QFileDialog.getOpenFileName(
        win, "Open session", "", "Session (*.json);;All files (*)"
    )
    if path:
        win.open_session(path, wait=False)


def mode_grid_dialog(win) -> None:
    """File > Export mode grid: modes of the spectrum shown side by side in one PNG
    (asked as "1-8" or "2,5,9"; one camera, the view's direction; one colour bar)."""
    import argparse

    from ..cli.common import mode_list

    operator = win.viewer.state.current_operator()
    spec = win.state.spectrum(operator) if operator is not None else None
    if spec is None:
        win.show_error("Compute a spectrum first: a mode grid shows its modes.")
        return
    first = win.state.display.mode if win.state.display.kind == "mode" else 1
    last = min(spec.k - 1, first + 7)
    text, ok = QtWidgets.QInputDialog.getText(
        win,
        "Export mode grid",
        f"Modes of {operator_info(operator).label} (e.g. 1-8 or 2,5,9; 0 .. {spec.k - 1}):",
        text=f"{first}-{last}",
    )
    if not ok:
        return
    try:
        modes = mode_list(text)
    except argparse.ArgumentTypeError as exc:
        win.show_error(str(exc))
        return
    start = Path(_picture_folder(win)) / "modes.png"
    write = lambda path: win.viewer.export_mode_grid(path, modes, operator)  # noqa: E731
    _save_as(win, "mode grid", "Export mode grid", start, "PNG (*.png)", write)
