"""Dialogs: screenshot export options, yes/no questions."""

from __future__ import annotations

import os
from pathlib import Path

from qtpy import QtWidgets


def file_message(path, message: str) -> str:
    """``message`` about the file ``path``, naming the file (prefixed unless it does)."""
    name = Path(path).name
    return message if name in message else f"{name}: {message}"


def ask(parent, title: str, question: str, default_yes: bool = False) -> bool:
    """A yes/no question (default No; ``default_yes`` where Yes is the action the user
    asked for).  With MODALVIEWER_NO_DIALOGS set (tests, scripts) the answer is
    MODALVIEWER_ASSUME_YES, so nothing starts without being asked for."""
    if os.environ.get("MODALVIEWER_NO_DIALOGS"):
        return bool(os.environ.get("MODALVIEWER_ASSUME_YES"))
    buttons = QtWidgets.QMessageBox.StandardButton
    default = buttons.Yes if default_yes else buttons.No
    answer = QtWidgets.QMessageBox.question(
        parent, title, question, buttons.Yes | buttons.No, default
    )
    return answer == buttons.Yes


def ask_action(parent, title: str, text: str, action: str) -> bool:
    """A question with the button ``action`` (the default: what the user asked for) and
    Cancel; True if ``action`` was chosen.  With MODALVIEWER_NO_DIALOGS set the answer
    is MODALVIEWER_ASSUME_YES, as for :func:`ask`."""
    if os.environ.get("MODALVIEWER_NO_DIALOGS"):
        return bool(os.environ.get("MODALVIEWER_ASSUME_YES"))
    box = QtWidgets.QMessageBox(QtWidgets.QMessageBox.Icon.Warning, title, text, parent=parent)
    chosen = box.addButton(action, QtWidgets.QMessageBox.ButtonRole.AcceptRole)
    box.addButton(QtWidgets.QMessageBox.StandardButton.Cancel)
    box.setDefaultButton(chosen)
    box.exec()
    return box.clickedButton() is chosen


DAMAGED_WORDS = "the file is damaged or truncated"
"""How ``window.last_error`` ends for a file refused as damaged (:func:`offer_open_anyway`):
a run without a display tells from it that ``--partial`` would open the file."""


def offer_open_anyway(window, path, error: Exception) -> bool:
    """Name the damage of a file that did not load (status bar, ``window.last_error``)
    and ask whether to load its whole records; True for "Open anyway" (the default)."""
    message = file_message(path, str(error)).split("; the file is damaged")[0]
    window.last_error = f"{message}; {DAMAGED_WORDS}"
    window.statusBar().showMessage(message, 10000)
    return ask_action(
        window,
        "Damaged file",
        f"{message}.\n\nThe file is damaged or truncated. Open anyway loads the "
        "records that are whole and reports what was dropped.",
        "Open anyway",
    )


class ScreenshotDialog(QtWidgets.QDialog):
    """File, size multiplier, transparent background, colour bar and legend."""

    def __init__(self, parent, start_dir: str, colorbar: bool = False):
        super().__init__(parent)
        self.setWindowTitle("Export screenshot")
        form = QtWidgets.QFormLayout(self)
        self.path_edit = QtWidgets.QLineEdit(str(Path(start_dir) / "figure.png"))
        self.path_edit.setMinimumWidth(420)
        browse = QtWidgets.QPushButton("...")
        browse.clicked.connect(self._browse)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.path_edit)
        row.addWidget(browse)
        form.addRow("File", row)
        self.scale = QtWidgets.QSpinBox()
        self.scale.setRange(1, 8)
        self.transparent = QtWidgets.QCheckBox("Transparent background")
        self.colorbar = QtWidgets.QCheckBox("Colour bar and legend")
        self.colorbar.setChecked(colorbar)
        form.addRow("Size multiplier", self.scale)
        form.addRow(self.transparent)
        form.addRow(self.colorbar)
        buttons = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.StandardButton.Save
            | QtWidgets.QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _browse(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Screenshot", self.path_edit.text(), "PNG (*.png)"
        )
        if path:
            self.path_edit.setText(path)

    def values(self):
        return (
            self.path_edit.text(),
            self.scale.value(),
            self.transparent.isChecked(),
            self.colorbar.isChecked(),
        )
