"""Computations as job objects: each its own progress, cancel, result or error (no Qt).

One job runs at a time (a spectrum computation already uses every core), the others wait
first in, first out; a request with the ``key`` of a queued or running job joins it.  A
job's function runs in a worker thread; every state change is handed to ``dispatch``
(Qt's event loop, or :class:`ManualDispatcher` in scripts), so ``events`` are emitted on
the owner's thread.
"""

from __future__ import annotations

import itertools
import queue
import threading
import time
import traceback
from collections.abc import Callable, Hashable

from psygnal import Signal, SignalGroup

from ..core.eigen import Cancelled, EigenError
from ..core.mesh import MeshError
from .process import ChildError

_ids = itertools.count(1)

# failures whose message says it all: their jobs keep no traceback for the log
EXPECTED_FAILURES: tuple[type[Exception], ...] = (MeshError, EigenError, ChildError)
PROGRESS_INTERVAL = 0.05  # seconds between reports of one stage (each crosses threads)
NO_MEMORY = "Not enough memory for this computation; compute fewer modes or use Coarse-to-fine."

QUEUED, RUNNING, DONE, FAILED, CANCELLED = "queued", "running", "done", "failed", "cancelled"


class Job:
    """One computation: ``fn(progress, cancel)`` returns the result.  ``error`` is for
    users, ``details`` a traceback for the log, ``said`` what the status line said of it."""

    def __init__(self, fn: Callable, key: Hashable, description: str, owner: Hashable = None):
        self.id = next(_ids)
        self.key = key
        self.owner = owner
        self.description = description
        self.status = QUEUED
        self.stage = "queued"
        self.fraction = 0.0
        self.result = None
        self.error: str | None = None
        self.details = ""
        self.seconds = 0.0
        self.said: list[str] = []
        self.callbacks: list[Callable[[Job], None]] = []
        self._fn = fn
        self._cancel = threading.Event()
        self._done = threading.Event()

    def __repr__(self) -> str:
        return f"<Job {self.id} {self.description!r} {self.status}>"

    @property
    def done(self) -> bool:
        return self.status in (DONE, FAILED, CANCELLED)

    @property
    def cancel_requested(self) -> bool:
        return self._cancel.is_set()

    def cancel(self) -> None:
        """Ask the job to stop; a queued job is dropped when its turn comes."""
        self._cancel.set()

    def end_now(self, result) -> Job:
        """Mark this (never queued) job ended with ``result``: a request answered at once."""
        self.status, self.stage, self.fraction, self.result = DONE, "done", 1.0, result
        self._done.set()
        return self

    def then(self, callback: Callable[[Job], None]) -> Job:
        """Call ``callback(job)`` on the owner's thread once the job has ended (or now)."""
        if self.done:
            callback(self)
        else:
            self.callbacks.append(callback)
        return self

    def join(self, timeout: float | None = None) -> bool:
        """Block until the worker thread has finished (not until callbacks ran)."""
        return self._done.wait(timeout)


class SpectrumJob(Job):
    """A job computing the spectrum ``spectrum_key``; result ``(Spectrum, table or None)``."""

    def __init__(self, fn, key, description, owner, spectrum_key) -> None:
        super().__init__(fn, key, description, owner)
        self.spectrum_key = spectrum_key


class RepairJob(Job):
    """A job repairing a mesh (``modalviewer.repair.REPAIRS``); result the repaired Mesh."""


class LatestModes:
    """``on_modes`` of a spectrum computation (worker thread): keeps the latest spectrum
    and dispatches one ``deliver(spectrum)`` at a time, so a slow redraw skips steps
    rather than queueing them; nothing once ``job`` was cancelled or has ended."""

    def __init__(self, dispatch: Callable[[Callable[[], None]], None], deliver) -> None:
        self.dispatch, self.deliver = dispatch, deliver
        self.job: Job | None = None
        self._latest = None
        self._pending = False
        self._lock = threading.Lock()

    def __call__(self, spectrum) -> None:
        if spectrum.is_complete:
            return
        with self._lock:
            self._latest = spectrum
            if self._pending:
                return
            self._pending = True
        self.dispatch(self._deliver)

    def _deliver(self) -> None:
        with self._lock:
            spectrum, self._pending = self._latest, False
        job = self.job
        if job is not None and not job.done and not job.cancel_requested:
            self.deliver(spectrum)


class JobEvents(SignalGroup):
    changed = Signal(object)  # a job was queued, started, progressed or ended
    finished = Signal(object)  # a job ended (done, failed or cancelled)


class ManualDispatcher:
    """Collects functions from worker threads; :meth:`process` runs them here."""

    def __init__(self) -> None:
        self._queue: queue.Queue = queue.Queue()

    def __call__(self, fn: Callable[[], None]) -> None:
        self._queue.put(fn)

    def process(self, timeout: float = 0.0) -> None:
        """Run the pending functions (waiting up to ``timeout`` s for the first)."""
        try:
            fn = self._queue.get(timeout=timeout) if timeout > 0 else self._queue.get_nowait()
            while True:
                fn()
                fn = self._queue.get_nowait()
        except queue.Empty:
            pass


class JobQueue:
    """Runs jobs one at a time in worker threads; see the module docstring."""

    def __init__(self, dispatch: Callable[[Callable[[], None]], None] | None = None):
        self.dispatch = dispatch or ManualDispatcher()
        self.events = JobEvents()
        self.jobs: list[Job] = []  # queued and running, in order

    # -------------------------------------------------------------- public
    def submit(self, fn: Callable, key: Hashable, description: str, owner: Hashable = None) -> Job:
        """Queue ``fn`` as a plain :class:`Job`; see :meth:`add`."""
        return self.add(Job(fn, key, description, owner))

    def add(self, job: Job) -> Job:
        """Queue ``job``, or return a queued or running one of the same ``key``."""
        for queued in self.jobs:
            if queued.key == job.key and not queued.cancel_requested:
                return queued
        self.jobs.append(job)
        self.events.changed.emit(job)
        self._start_next()
        return job

    def add_spectrum(
        self, make_work, key: Hashable, description: str, owner: Hashable, spectrum_key, deliver
    ) -> SpectrumJob:
        """Queue a :class:`SpectrumJob` running ``make_work(on_modes)``; the modes handed
        to ``on_modes`` reach ``deliver(spectrum)`` on the owner's thread."""
        arrivals = LatestModes(self.dispatch, deliver)
        job = self.add(SpectrumJob(make_work(arrivals), key, description, owner, spectrum_key))
        arrivals.job = job
        return job

    @property
    def running(self) -> Job | None:
        return next((job for job in self.jobs if job.status == RUNNING), None)

    @property
    def busy(self) -> bool:
        return bool(self.jobs)

    def cancel(self, job: Job) -> None:
        """Cancel ``job``: a queued one ends at once, a running one at its next check."""
        job.cancel()
        if job.status == QUEUED:
            self._end(job, CANCELLED, error="cancelled")
            self._start_next()

    def cancel_all(self, owner: Hashable = None, reason: str = "cancelled") -> None:
        """Cancel every job (of ``owner`` only, if given)."""
        for job in list(self.jobs):
            if owner is None or job.owner == owner:
                job.cancel()
                if job.status == QUEUED:
                    self._end(job, CANCELLED, error=reason)
                else:
                    job.error = reason
        self._start_next()

    def wait(self, job: Job, timeout: float | None = None) -> Job:
        """Wait for ``job`` here, running dispatched functions (scripts and tests)."""
        if not isinstance(self.dispatch, ManualDispatcher):
            raise RuntimeError("this queue's events run in an event loop: wait there")
        deadline = None if timeout is None else time.monotonic() + timeout
        while not job.done:
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"{job.description} did not end within {timeout} s")
            self.dispatch.process(timeout=0.05)
        return job

    def shutdown(self, timeout: float = 5.0) -> None:
        """Cancel everything and wait for the running worker (window closing)."""
        running = self.running
        self.cancel_all(reason="the window was closed")
        if running is not None:
            running.join(timeout)
            self._end(running, CANCELLED, "the window was closed")

    # ------------------------------------------------------------ internal
    def _start_next(self) -> None:
        job = next((j for j in self.jobs if j.status == QUEUED), None)
        if job is None or self.running is not None:
            return
        job.status, job.stage = RUNNING, "starting"
        job._started = time.perf_counter()
        self.events.changed.emit(job)
        threading.Thread(target=self._run, args=(job,), daemon=True).start()

    def _run(self, job: Job) -> None:
        last = {"stage": None, "time": 0.0}

        def progress(stage: str, fraction: float) -> None:
            now = time.monotonic()
            if stage == last["stage"] and now - last["time"] < PROGRESS_INTERVAL:
                return
            last.update(stage=stage, time=now)
            self.dispatch(lambda: self._progress(job, str(stage), float(fraction)))

        try:
            result = job._fn(progress, job._cancel.is_set)
        except Cancelled as exc:  # a reason given by the work itself is kept
            outcome = (CANCELLED, None, job.error or str(exc) or "cancelled", "")
        except MemoryError:
            outcome = (FAILED, None, NO_MEMORY, traceback.format_exc())
        except EXPECTED_FAILURES as exc:  # the message says it all: no traceback
            outcome = (FAILED, None, str(exc) or type(exc).__name__, "")
        except Exception as exc:  # reported to the user, never raised into the event loop
            outcome = (FAILED, None, str(exc) or type(exc).__name__, traceback.format_exc())
        else:
            cancelled = (CANCELLED, None, job.error or "cancelled", "")
            outcome = cancelled if job._cancel.is_set() else (DONE, result, None, "")
        job.seconds = time.perf_counter() - job._started
        job._done.set()
        self.dispatch(lambda: self._finish(job, *outcome))

    def _progress(self, job: Job, stage: str, fraction: float) -> None:
        if job.status != RUNNING:
            return
        job.stage, job.fraction = stage, fraction
        self.events.changed.emit(job)

    def _finish(self, job: Job, status, result, error, details) -> None:
        job.result, job.details = result, details
        try:
            self._end(job, status, error)
        finally:
            self._start_next()

    def _end(self, job: Job, status: str, error: str | None) -> None:
        """Mark ``job`` ended, tell the observers, then run its callbacks even if an
        observer raised (a wait would never end; the error is raised afterwards)."""
        if job.done:
            return
        job.status, job.error = status, error
        if job in self.jobs:
            self.jobs.remove(job)
        try:
            self.events.changed.emit(job)
            self.events.finished.emit(job)
        finally:
            for callback in job.callbacks:
                callback(job)
