"""Dialogs: screenshot export options, yes/no questions."""

from __future__ import annotations

import os
from pathlib import Path

from qtpy import QtWidgets

from .panels.common import row, spin_box


def file_message(path, message: str) -> str:
    """``message`` about the file ``path``, naming the file (prefixed unless it does)."""
    name = Path(path).name
    return message if name in message else f"{name}: {message}"


def ask(parent, title: str, question: str, default_yes: bool = False, action=None) -> bool:
    """A yes/no question (default No; ``default_yes`` where Yes is the action the user
    asked for), or with ``action`` a warning with that button (the default) and Cancel.
    With MODALVIEWER_NO_DIALOGS set (tests, scripts) the answer is
    MODALVIEWER_ASSUME_YES, so nothing starts without being asked for."""
    if os.environ.get("MODALVIEWER_NO_DIALOGS"):
        return bool(os.environ.get("MODALVIEWER_ASSUME_YES"))
    icon = QtWidgets.QMessageBox.Icon.Warning if action else QtWidgets.QMessageBox.Icon.Question
    box = QtWidgets.QMessageBox(icon, title, question, parent=parent)
    buttons = QtWidgets.QMessageBox.StandardButton
    role = QtWidgets.QMessageBox.ButtonRole.AcceptRole
    yes = box.addButton(action, role) if action else box.addButton(buttons.Yes)
    no = box.addButton(buttons.Cancel if action else buttons.No)
    box.setDefaultButton(yes if action or default_yes else no)
    box.exec()
    return box.clickedButton() is yes


NO_MESH_A = "Open a mesh first: it becomes mesh A of the pair."

DAMAGED_WORDS = "the file is damaged or truncated"
"""How ``window.last_error`` ends for a file refused as damaged (:func:`offer_open_anyway`):
a run without a display tells from it that ``--partial`` would open the file."""


def offer_open_anyway(window, path, error: Exception) -> bool:
    """Name the damage of a file that did not load (status bar, ``window.last_error``)
    and ask whether to load its whole records; True for "Open anyway" (the default)."""
    message = file_message(path, str(error)).split("; the file is damaged")[0]
    window.viewer.last_error = f"{message}; {DAMAGED_WORDS}"
    window.statusBar().showMessage(message, 10000)
    return ask(
        window,
        "Damaged file",
        f"{message}.\n\nThe file is damaged or truncated. Open anyway loads the "
        "records that are whole and reports what was dropped.",
        action="Open anyway",
    )


def _size_boxes(form, size) -> tuple:
    """Width and height spin boxes (pixels) on one row of ``form``, set to ``size``."""
    width, height = (spin_box(16, 8192, value, suffix=" px") for value in size)
    form.addRow("Width x height", row(width, "x", height, 1))
    return width, height


class _ExportDialog(QtWidgets.QDialog):
    """A form with the file to write (a field and a browse button) and, once
    :meth:`_finish` is called, Save and Cancel."""

    def __init__(self, parent, title: str, path: Path, filters: str):
        super().__init__(parent, windowTitle=title)
        self.filters = filters
        self.form = QtWidgets.QFormLayout(self)
        self.path_edit = QtWidgets.QLineEdit(str(path), minimumWidth=420)
        browse = QtWidgets.QPushButton("...", clicked=self._browse)
        self.form.addRow("File", row(self.path_edit, browse))

    def _finish(self) -> None:
        standard = QtWidgets.QDialogButtonBox.StandardButton
        buttons = standard.Save | standard.Cancel
        self.form.addRow(
            QtWidgets.QDialogButtonBox(buttons, accepted=self.accept, rejected=self.reject)
        )

    def _browse(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, self.windowTitle(), self.path_edit.text(), self.filters
        )
        if path:
            self.path_edit.setText(path)


class ScreenshotDialog(_ExportDialog):
    """File, width and height in pixels (not asked with ``size`` None), size
    multiplier, transparent background, colour bar and legend, pick marker (not asked
    with ``marker`` None)."""

    def __init__(
        self, parent, start_dir: str, colorbar: bool = False, size=(1024, 768), marker=False
    ):
        super().__init__(parent, "Export screenshot", Path(start_dir) / "figure.png", "PNG (*.png)")
        form = self.form
        self.width_box = self.height_box = None
        if size is not None:
            self.width_box, self.height_box = _size_boxes(form, size)
        self.scale = spin_box(1, 8)
        self.transparent = QtWidgets.QCheckBox("Transparent background")
        self.colorbar = QtWidgets.QCheckBox("Colour bar and legend", checked=colorbar)
        self.marker = QtWidgets.QCheckBox(
            "Pick marker",
            checked=bool(marker),
            toolTip="The picked vertex's marker (shown on distance maps by default)",
        )
        form.addRow("Size multiplier", self.scale)
        form.addRow(self.transparent)
        form.addRow(self.colorbar)
        if marker is not None:
            form.addRow(self.marker)
        self._finish()

    def values(self):
        """(path, scale, transparent, colour bar, (width, height) or None, marker)."""
        size = None if self.width_box is None else (self.width_box.value(), self.height_box.value())
        return (
            self.path_edit.text(),
            self.scale.value(),
            self.transparent.isChecked(),
            self.colorbar.isChecked(),
            size,
            self.marker.isChecked(),
        )


class AnimationDialog(_ExportDialog):
    """File (.gif, or .mp4 where its writer is installed), width and height, frames in
    one period and frames per second."""

    def __init__(self, parent, start_dir: str, size=(640, 480), frames: int = 52, fps: int = 25):
        from ..scene.animation import mp4_available

        filters = "GIF (*.gif)" + (";;MP4 (*.mp4)" if mp4_available() else "")
        super().__init__(parent, "Export animation", Path(start_dir) / "mode.gif", filters)
        form = self.form
        self.width_box, self.height_box = _size_boxes(form, size)
        self.frames = spin_box(2, 1000, frames)
        self.fps = spin_box(1, 100, fps)
        form.addRow("Frames in one period", self.frames)
        form.addRow("Frames per second", self.fps)
        if not mp4_available():
            note = "MP4 needs imageio-ffmpeg: pip install 'modalviewer[video]'"
            form.addRow(QtWidgets.QLabel(note, wordWrap=True))
        self._finish()

    def values(self):
        """(path, (width, height), frames, fps)."""
        return (
            self.path_edit.text(),
            (self.width_box.value(), self.height_box.value()),
            self.frames.value(),
            self.fps.value(),
        )
