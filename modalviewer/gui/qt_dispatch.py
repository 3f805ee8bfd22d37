"""Runs functions from worker threads on the GUI thread (the jobs' dispatcher)."""

from __future__ import annotations

from collections.abc import Callable

from qtpy import QtCore


class QtDispatcher(QtCore.QObject):
    """``dispatcher(fn)`` from any thread: ``fn()`` runs on this object's thread, in
    order, through a queued signal."""

    _call = QtCore.Signal(object)

    def __init__(self, parent=None):
        super().__init__(parent)
        self._call.connect(self._run, QtCore.Qt.ConnectionType.QueuedConnection)

    def __call__(self, fn: Callable[[], None]) -> None:
        self._call.emit(fn)

    @staticmethod
    def _run(fn) -> None:
        fn()
