"""The main window's status bar: the status line (what is shown), the progress bar of
the running computation and its Cancel button."""

from __future__ import annotations

from qtpy import QtWidgets

from .panels import StatusLine


class StatusBarWidgets:
    """The permanent widgets of ``bar``, following ``state`` and the ``jobs`` queue."""

    STATUS_LINE_WIDTH = 620
    """Widest the status line gets; :data:`STATUS_LINE_WIDTH_BESIDE_MESSAGE` while a
    temporary message is shown, which needs the room more (what is computing and why)."""
    STATUS_LINE_WIDTH_BESIDE_MESSAGE = 300
    STAGE_CHARS = 30
    """Characters of the running stage the progress bar shows (longer ones are cut, whole
    in its tooltip and in the Computations list)."""

    def __init__(self, bar: QtWidgets.QStatusBar, state, jobs):
        self.bar = bar
        self.jobs = jobs
        self.status_line = StatusLine(state)
        self.status_line.setMaximumWidth(self.STATUS_LINE_WIDTH)
        bar.addPermanentWidget(self.status_line)
        self.progress = QtWidgets.QProgressBar()
        self.progress.setFixedWidth(260)
        self.progress.setRange(0, 1000)
        self.progress.hide()
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setToolTip("Cancel the running computation (Esc)")
        self.cancel_button.hide()
        bar.addPermanentWidget(self.progress)
        bar.addPermanentWidget(self.cancel_button)
        # the message shares the bar with the status line: while one is shown the status
        # line (elided, whole in its tooltip) gives it room; whole message on hover
        bar.messageChanged.connect(self._on_message)
        jobs.events.changed.connect(self._on_job_changed)

    def _on_message(self, text: str) -> None:
        self.bar.setToolTip(text)
        self.status_line.setMaximumWidth(
            self.STATUS_LINE_WIDTH_BESIDE_MESSAGE if text else self.STATUS_LINE_WIDTH
        )

    def _on_job_changed(self, _job) -> None:
        running = self.jobs.running
        self.progress.setVisible(running is not None)
        self.cancel_button.setVisible(running is not None)
        if running is not None:
            self.progress.setValue(int(1000 * running.fraction))
            queued = len(self.jobs.jobs) - 1
            more = f" (+{queued} queued)" if queued else ""
            stage = running.stage
            if len(stage) > self.STAGE_CHARS:
                stage = stage[: self.STAGE_CHARS - 1] + "…"
            self.progress.setFormat(f"{stage} %p %{more}")  # as in the Computations list
            self.progress.setToolTip(f"{running.description}: {running.stage}")
