"""The base of the windows of several 3D views beside the main window (comparison, shape
pair): their keys, rendering, export and closing."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from qtpy import QtCore, QtGui, QtWidgets

from .viewport import save_views


class ViewsWindow(QtWidgets.QWidget):
    """A window of 3D views (``viewports`` and their ``scenes``, lists or dicts by side)
    beside ``main``; Ctrl+E exports them as one picture, under the name and with the
    dialog title :attr:`EXPORT`."""

    EXPORT = ("views.png", "Export the views")

    def install_keys(self, keys: list[tuple[str, Callable[[], None]]]) -> None:
        """``keys`` (key sequence text, slot) and Ctrl+E, served two ways: on a desktop
        the focused 3D view takes key presses before :meth:`keyPressEvent`, so window
        shortcuts come first; off screen shortcuts do not fire and
        :meth:`keyPressEvent` runs the slot."""
        keys = [*keys, ("Ctrl+E", self.export_dialog)]
        self._keys = {QtGui.QKeySequence(key).toString(): slot for key, slot in keys}
        for key, slot in self._keys.items():
            shortcut = QtGui.QShortcut(QtGui.QKeySequence(key), self)
            shortcut.setContext(QtCore.Qt.ShortcutContext.WidgetWithChildrenShortcut)
            shortcut.activated.connect(slot)

    def keyPressEvent(self, event):  # noqa: N802
        slot = self._keys.get(QtGui.QKeySequence(event.keyCombination()).toString())
        if slot is None:
            super().keyPressEvent(event)
        else:
            slot()

    def views(self) -> tuple[list, list]:
        """The viewports and their scenes, left to right."""
        listed = [getattr(x, "values", lambda x=x: x)() for x in (self.viewports, self.scenes)]
        return list(listed[0]), list(listed[1])

    def render_all(self) -> None:
        for viewport in self.views()[0]:
            viewport.request_render()

    def captions(self) -> list[str] | None:
        """The titles written above the views in an exported picture (None: no titles)."""
        return None

    def export_screenshot(self, path, scale: int = 1, transparent: bool = False) -> Path:
        """The views side by side, each with its legend and colour bar (and its caption),
        in one PNG written atomically."""
        viewports, scenes = self.views()
        return save_views(path, viewports, scenes, scale, transparent, self.captions())

    def export_dialog(self) -> None:
        from .file_dialogs import window_screenshot_dialog

        window_screenshot_dialog(self, *self.EXPORT)

    def close_views(self) -> None:
        for viewport in self.views()[0]:
            viewport.close_plotter()
