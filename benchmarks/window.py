"""The viewer's main window for benchmarks: off-screen, an empty cache, and a clock of the
event loop's gaps (how long the window could not react)."""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("MODALVIEWER_NO_DIALOGS", "1")
if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def bench_window():
    """(application, the main window at 1280 x 900, shown) with a fresh empty cache."""
    from qtpy import QtWidgets

    from modalviewer.core.cache import SpectrumCache
    from modalviewer.gui import MainWindow

    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication([])
    win = MainWindow(
        force_offscreen=True,
        cache=SpectrumCache(Path(tempfile.mkdtemp(prefix="modalviewer-bench-"))),
    )
    win.resize(1280, 900)
    win.show()
    app.processEvents()
    return app, win


class EventLoopGaps:
    """A 10 ms timer on the event loop; ``gaps`` holds the seconds between its ticks
    since the last :meth:`reset` (long gaps: the window did not react)."""

    def __init__(self) -> None:
        from qtpy import QtCore

        self.gaps: list[float] = []
        self._last = time.perf_counter()
        self._timer = QtCore.QTimer()
        self._timer.timeout.connect(self._tick)
        self._timer.start(10)

    def _tick(self) -> None:
        now = time.perf_counter()
        self.gaps.append(now - self._last)
        self._last = now

    def reset(self) -> list[float]:
        """Start counting again; returns the gaps counted so far."""
        gaps, self.gaps = self.gaps, []
        self._last = time.perf_counter()
        return gaps

    def longest_ms(self) -> float | None:
        return 1e3 * max(self.gaps) if self.gaps else None

    def stop(self) -> None:
        self._timer.stop()
