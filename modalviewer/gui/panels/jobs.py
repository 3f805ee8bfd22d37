"""Jobs panel: the running and queued computations, each with its own Cancel, and how the
last one ended (the status line's message about it gives way to the next)."""

from __future__ import annotations

from qtpy import QtCore, QtWidgets

from ...viewer.jobs import RUNNING, Job, JobQueue
from ...viewer.wording import ended_text
from .common import WrappingLabel


class JobsPanel(QtWidgets.QWidget):
    """One row per queued or running job (description, progress, Cancel) and "Last:", how
    the last job of the mesh on screen ended, cleared when another mesh is opened (a job
    of the old mesh does not fill it again)."""

    def __init__(self, jobs: JobQueue, state, parent=None):
        super().__init__(parent)
        self.jobs = jobs
        self.state = state
        self.layout_ = QtWidgets.QVBoxLayout(self)
        self.layout_.setContentsMargins(0, 0, 0, 0)
        self.empty = QtWidgets.QLabel("No computation running.")
        self.layout_.addWidget(self.empty)
        self.last = WrappingLabel("")
        self.last.hide()
        self.layout_.addWidget(self.last)
        self.rows: dict[int, tuple[QtWidgets.QWidget, QtWidgets.QLabel]] = {}
        jobs.events.changed.connect(self._on_changed)
        state.events.mesh.connect(self._on_mesh)

    def _on_mesh(self) -> None:
        self.last.clear()
        self.last.hide()

    def _on_changed(self, job: Job) -> None:
        row = self.rows.get(job.id)
        if job.done:
            if row is not None:
                row[0].deleteLater()
                del self.rows[job.id]
                mesh = self.state.mesh  # a job of another mesh says nothing of this one
                if job.owner is None or mesh is None or job.owner == mesh.hash:
                    self.last.setText(f"Last: {ended_text(job)}")
                    self.last.show()
        else:
            if row is None:
                row = self._make_row(job)
                self.rows[job.id] = row
            state = (
                f"{job.stage} {int(100 * job.fraction)} %" if job.status == RUNNING else "queued"
            )
            said = "\n".join(job.said) or job.description  # whole, where the bar cuts it
            row[1].setText(f"{said}\n{state}")
        self.empty.setVisible(not self.rows)

    def _make_row(self, job: Job):
        widget = QtWidgets.QWidget()
        lay = QtWidgets.QHBoxLayout(widget)
        lay.setContentsMargins(0, 0, 0, 0)
        label = WrappingLabel()
        button = QtWidgets.QPushButton("Cancel", toolTip="Cancel this computation")
        button.clicked.connect(lambda: self.jobs.cancel(job))
        lay.addWidget(label, 1)
        lay.addWidget(button, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        self.layout_.addWidget(widget)
        return widget, label
