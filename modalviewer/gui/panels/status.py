"""The status line: the current display's live numbers, always in sync with the state."""

from __future__ import annotations

from qtpy import QtWidgets

from ...viewer.state import ViewerState


class StatusLine(QtWidgets.QLabel):
    """A permanent status-bar label showing ``state.summary()``."""

    def __init__(self, state: ViewerState, parent=None):
        super().__init__(parent)
        self.state = state
        # framed, so a temporary message to its left ("Computing ...") does not read as
        # the start of the same line
        self.setFrameShape(QtWidgets.QFrame.Shape.StyledPanel)
        for event in (
            state.events.display,
            state.events.pick,
            state.events.spectra,
            state.events.mesh,
            state.events.style,
        ):
            event.connect(self.update_from_state)
        self.update_from_state()

    def update_from_state(self, *_args) -> None:
        self.setText(self.state.summary())
