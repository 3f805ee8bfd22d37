"""Background jobs: run a function in a thread, report progress, allow cancel.

Signals cross to the GUI thread through Qt's queued connections; each job carries an
id so the window can drop results of jobs it no longer cares about.
"""

from __future__ import annotations

import itertools
import threading
import time
import traceback
from collections.abc import Callable

import numpy as np
from qtpy import QtCore

from ..core.eigen import Cancelled

_ids = itertools.count(1)

PROGRESS_INTERVAL = 0.05
"""Seconds between two progress signals of the same stage."""


class Job(QtCore.QObject):
    """One background computation: ``fn(progress, cancel)`` returns the result."""

    progress = QtCore.Signal(int, str, float)
    finished = QtCore.Signal(int, object)
    failed = QtCore.Signal(int, str, str)  # id, message for the user, details for the log
    cancelled = QtCore.Signal(int)

    def __init__(self, fn: Callable, tag: object = None):
        super().__init__()
        self.id = next(_ids)
        self.tag = tag
        self._fn = fn
        self._cancel = threading.Event()
        self._last_stage: str | None = None
        self._last_emit = 0.0
        self._thread = threading.Thread(
            target=self._run, name=f"modalviewer-job-{self.id}", daemon=True
        )

    def start(self) -> None:
        self._thread.start()

    def cancel(self) -> None:
        self._cancel.set()

    @property
    def is_cancelled(self) -> bool:
        return self._cancel.is_set()

    def is_running(self) -> bool:
        return self._thread.is_alive()

    def wait(self, timeout: float | None = None) -> bool:
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def _emit_progress(self, stage: str, fraction: float) -> None:
        """Forward progress at most every 50 ms (and on every new stage): a solver may
        report hundreds of times a second, and each report crosses to the GUI thread."""
        now = time.monotonic()
        if stage == self._last_stage and now - self._last_emit < PROGRESS_INTERVAL:
            return
        self._last_stage, self._last_emit = stage, now
        self.progress.emit(self.id, str(stage), float(fraction))

    def _run(self) -> None:
        try:
            result = self._fn(self._emit_progress, self._cancel.is_set)
        except Cancelled:
            self.cancelled.emit(self.id)
        except MemoryError:
            self.failed.emit(
                self.id,
                "Not enough memory for this computation; try fewer modes or a coarser mesh.",
                traceback.format_exc(),
            )
        except Exception as exc:  # reported to the user, never raised into Qt
            self.failed.emit(self.id, str(exc) or type(exc).__name__, traceback.format_exc())
        else:
            if self._cancel.is_set():
                self.cancelled.emit(self.id)
            else:
                self.finished.emit(self.id, result)


def compute_in_process(mesh, operator, k, bending, membrane, out_path, progress, cancel):
    """Run ``modalviewer.core.job_main`` in a child Python; relay progress; kill on cancel.

    Returns the Spectrum read back from ``out_path``; the child's error message is
    raised as RuntimeError.
    """
    import json
    import os
    import queue
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    from ..core.spectrum import load_spectrum

    params = {"operator": operator, "k": int(k), "bending": bending, "membrane": membrane}
    fd, job_path = tempfile.mkstemp(prefix="modalviewer-job-", suffix=".npz")
    os.close(fd)
    np.savez(job_path, vertices=mesh.vertices, faces=mesh.faces, params=json.dumps(params))
    child = subprocess.Popen(
        [sys.executable, "-m", "modalviewer.core.job_main", job_path, str(out_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        text=True,
    )
    lines: queue.Queue = queue.Queue()

    def pump():
        for line in child.stdout:
            lines.put(line)
        lines.put(None)

    threading.Thread(target=pump, daemon=True).start()
    progress("starting", 0.0)
    error = None
    try:
        while True:
            if cancel():
                raise Cancelled()
            try:
                line = lines.get(timeout=0.05)
            except queue.Empty:
                continue
            if line is None:
                break
            try:
                message = json.loads(line)
            except json.JSONDecodeError:
                continue
            if "stage" in message:
                progress(message["stage"], message["fraction"])
            elif "error" in message:
                error = message["error"]
    finally:
        if child.poll() is None:
            child.kill()
        child.wait()
        Path(job_path).unlink(missing_ok=True)
    if error is not None:
        raise RuntimeError(error)
    if child.returncode != 0:
        raise RuntimeError(
            f"the computation process stopped unexpectedly (exit code {child.returncode}); "
            "it may have run out of memory"
        )
    return load_spectrum(out_path, mesh_hash=mesh.hash)
