"""The main window's status bar: the status line (what is shown, always in sync with the
state), the progress bar of the running computation and its Cancel button."""

from __future__ import annotations

from qtpy import QtCore, QtGui, QtWidgets

from ..viewer.jobs import RUNNING
from ..viewer.wording import summary
from .panels.common import follow


class StatusLine(QtWidgets.QLabel):
    """A permanent status-bar label showing :func:`~modalviewer.viewer.wording.summary`."""

    def __init__(self, state, parent=None):
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


class JobProgress:
    """A progress bar and its Cancel button showing jobs (hidden without any), the
    running one first: [its name:] its stage, percentage and how many wait; what comes
    before the percentage is shortened with an ellipsis where the bar is too narrow."""

    def __init__(self, width: tuple[int, int], cancel_tip: str, cancel, named: bool = True):
        self.named = named
        self.bar = QtWidgets.QProgressBar(
            maximum=1000, minimumWidth=width[0], maximumWidth=width[1]
        )
        self.cancel_button = QtWidgets.QPushButton("Cancel", toolTip=cancel_tip, clicked=cancel)
        self.show_jobs([])

    def show_jobs(self, jobs) -> None:
        for widget in (self.bar, self.cancel_button):
            widget.setVisible(bool(jobs))
        if not jobs:
            return
        job, more = jobs[0], f" (+{len(jobs) - 1} queued)" if len(jobs) > 1 else ""
        self.bar.setValue(int(1000 * job.fraction) if job.status == RUNNING else 0)
        if job.status != RUNNING:
            self.bar.setFormat(self._fitted(f"waiting: {job.description}", ""))
        elif self.named:
            self.bar.setFormat(self._fitted(job.description, f": {job.stage} %p %{more}"))
        else:  # as in the Computations list
            self.bar.setFormat(self._fitted(job.stage, f" %p %{more}"))
        self.bar.setToolTip(f"{job.description}: {job.stage}")  # the whole text

    def _fitted(self, head: str, tail: str) -> str:
        """``head`` elided to fit + ``tail`` ("%p" is the bar's percentage)."""
        metrics = self.bar.fontMetrics()
        room = self.bar.width() - 2 * metrics.horizontalAdvance("M")  # frame, margins
        tail_width = metrics.horizontalAdvance(tail.replace("%p", "100"))
        elide = QtCore.Qt.TextElideMode.ElideRight
        return metrics.elidedText(head, elide, max(0, room - tail_width)) + tail


class StatusBarWidgets:
    """The permanent widgets of ``bar``, following ``state`` and the ``jobs`` queue."""

    STATUS_LINE_WIDTH = 620
    """Widest the status line gets; :data:`STATUS_LINE_WIDTH_BESIDE_MESSAGE` while a
    temporary message is shown, which needs the room more (what is computing and why)."""
    STATUS_LINE_WIDTH_BESIDE_MESSAGE = 300

    def __init__(self, bar: QtWidgets.QStatusBar, state, jobs, cancel):
        self.bar = bar
        self.jobs = jobs
        self.status_line = StatusLine(state)
        self.status_line.setMaximumWidth(self.STATUS_LINE_WIDTH)
        bar.addPermanentWidget(self.status_line)
        cancel_tip = "Cancel the running computation (Esc)"
        self.progress = JobProgress((260, 260), cancel_tip, cancel, named=False)
        bar.addPermanentWidget(self.progress.bar)
        bar.addPermanentWidget(self.progress.cancel_button)
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
        others = [job for job in self.jobs.jobs if job is not running]
        self.progress.show_jobs([running, *others] if running is not None else [])
