"""The status line: the current display's live numbers, always in sync with the state."""

from __future__ import annotations

from qtpy import QtCore, QtGui, QtWidgets

from ...viewer.state import ViewerState
from ...viewer.wording import summary
from .common import follow


class StatusLine(QtWidgets.QLabel):
    """A permanent status-bar label showing :func:`~modalviewer.viewer.wording.summary`."""

    def __init__(self, state: ViewerState, parent=None):
        super().__init__(parent)
        self.state = state
        # framed, so a temporary message to its left ("Computing ...") does not read as
        # the start of the same line
        self.setFrameShape(QtWidgets.QFrame.Shape.StyledPanel)
        follow(state, self.update_from_state, "display", "pick", "spectra", "mesh", "style")
        self.update_from_state()

    def update_from_state(self, *_args) -> None:
        text = summary(self.state)
        self.setText(text)
        self.setToolTip(text)

    def minimumSizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt override)
        # narrower than its text: the text is elided (paintEvent), whole in the tooltip
        hint = super().minimumSizeHint()
        return QtCore.QSize(min(hint.width(), 160), hint.height())

    def paintEvent(self, event) -> None:  # noqa: N802
        """The text elided with "..." where the label is narrower than it (the status bar
        shares its width with messages), instead of cut off mid-word."""
        painter = QtGui.QPainter(self)
        self.drawFrame(painter)
        rect = self.contentsRect().adjusted(self.margin() + 3, 0, -self.margin() - 3, 0)
        text = self.fontMetrics().elidedText(
            self.text(), QtCore.Qt.TextElideMode.ElideRight, max(rect.width(), 0)
        )
        painter.drawText(rect, int(self.alignment()), text)
        painter.end()
