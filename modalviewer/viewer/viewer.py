"""The Viewer: everything the modalviewer window does, scripted without a window (no Qt).

A :class:`Viewer` is the model (:class:`~.model.ViewerModel`: evented state, job queue,
spectrum cache) with the scripting API, messages and pictures (:class:`~.pictures.Pictures`).
Scripts, notebooks, the command line and the windows drive the same object; a window
only wires widgets to it.  Messages are events: ``viewer.events.status(text,
milliseconds)``, ``error(title, text)``, ``info(title, text)`` and ``sliver_failure(key,
text)``; without a window nothing listens and scripts get return values and exceptions,
and worker results are handed back while a ``wait`` call waits
(:class:`~.jobs.ManualDispatcher`; a window installs its event loop,
:meth:`Viewer.use_event_loop`).
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np
from psygnal import Signal, SignalGroup

from ..core.cache import SpectrumCache
from ..core.mesh import Mesh, _plural
from ..core.operators import DISTANCE_KINDS, OPERATOR_INFO, operator_for_distance
from ..core.spectrum import Spectrum, in_input_numbering
from ..repair import repair_for_failure, repair_unavailable
from .comparison import Comparison
from .jobs import CANCELLED, DONE, FAILED, Job, ManualDispatcher, RepairJob, SpectrumJob
from .model import ComputeRefused, ViewerModel
from .pair import PairState
from .pictures import Pictures
from .session import restore_session, save_session
from .state import SpectrumKey
from .wording import ended_text, finished_text, memory_text, residual_text, seconds_text

log = logging.getLogger("modalviewer")

LONG_WAIT_SECONDS = 30.0
"""Requests expected to take longer (and showing nothing meanwhile) say so when they
start, with how long they will take and how to cancel."""


class ComputeError(RuntimeError):
    """A computation asked for by a script failed or was cancelled; the message says why."""


class ViewerMessages(SignalGroup):
    status = Signal(str, int)  # text, milliseconds to show it (0: until replaced)
    error = Signal(str, str)  # title, text
    info = Signal(str, str)  # title, text
    sliver_failure = Signal(object, str)  # SpectrumKey, text


class Viewer(ViewerModel, Pictures):
    """The viewer without a window.  ``cache``: where spectra are kept on disk (default:
    ``$MODALVIEWER_CACHE`` or the user's cache folder); ``dispatch``, ``waiter``: see
    :meth:`use_event_loop` (the defaults suit scripts)."""

    def __init__(self, cache: SpectrumCache | None = None, dispatch=None, waiter=None):
        super().__init__(cache, dispatch or ManualDispatcher(), waiter)
        self.events = ViewerMessages()
        self.last_error: str | None = None
        self.sliver_failure: SpectrumKey | None = None  # failed on slivers, to retry
        self._cancel_note = ""  # what a cancel left queued, said when the next job starts
        self._renderer = None  # the off-screen picture, made on the first export
        self._picture = None  # a window's picture source (see attach_picture)
        self.jobs.events.changed.connect(self._on_job_changed)
        self.jobs.events.finished.connect(self._on_job_finished)
        self.state.events.mesh.connect(self._on_mesh)

    def __repr__(self) -> str:
        mesh = self.state.mesh
        what = "no mesh" if mesh is None else f"{mesh.n_vertices} vertices"
        spectra = ", ".join(self.state.operators_computed()) or "no spectra"
        return f"<Viewer {what}; {spectra}; showing {self.state.display.kind}>"

    # ============================================================ plumbing
    def use_event_loop(self, dispatch, waiter) -> None:
        """Hand worker results to ``dispatch`` (a window's event loop) from now on and
        wait with ``waiter(job)``; results already handed back are delivered first."""
        old = self.jobs.dispatch
        self.jobs.dispatch = dispatch
        self._waiter = waiter
        if isinstance(old, ManualDispatcher):
            old.process()

    def _status(self, text: str, msec: int = 0) -> None:
        self.events.status.emit(text, msec)

    def report_error(self, text: str, title: str = "modalviewer") -> None:
        """Tell the user ``text`` (a window shows a dialog); kept as :attr:`last_error`."""
        self.last_error = text
        log.warning("%s", text)
        self.events.error.emit(title, text)

    # ============================================================== meshes
    @property
    def mesh(self) -> Mesh | None:
        """The loaded mesh, in its input's numbering (as loaded or given)."""
        return self.state.mesh.input_mesh if self.state.mesh is not None else None

    def _public(self, spec: Spectrum | None) -> Spectrum | None:
        """``spec`` in the input's numbering (one row per vertex of :attr:`mesh`)."""
        if spec is None or self.state.mesh is None:
            return spec
        return in_input_numbering(spec, self.state.mesh.input_mesh)

    def _on_mesh(self) -> None:
        if self.state.mesh is not None:  # what loading or a repair found and changed
            self._status(str(self.state.mesh.report), 15000)

    def repair_mesh(self, name: str, wait: bool = True) -> Mesh | None:
        """Apply repair ``name`` ("fix_slivers", "largest_component") in the background;
        the repaired mesh replaces the loaded one.  With ``wait`` returns it (ComputeError
        if the repair failed)."""
        job = self.repair(name).then(
            lambda j: self._status(str(j.result.report), 20000) if j.status == DONE else None
        )
        return self._waited(job).result if wait else None

    def fix_slivers_and_retry(self, key: SpectrumKey | None = None, wait: bool = False):
        """Fix the mesh's slivers and request again the spectrum ``key`` (default: the
        last one whose factorisation failed on slivers).  Returns the repair job (None if
        none started, e.g. without pymeshlab); with ``wait`` returns the spectrum."""
        key = key or self.sliver_failure
        if key is None:
            self._status("No computation failed on sliver triangles.", 5000)
            return None
        missing = repair_unavailable("fix_slivers")
        if missing:
            self.report_error(missing, "Fix slivers")
            return None
        try:
            job = self.repair("fix_slivers")
        except ValueError as exc:
            self.report_error(str(exc))
            return None
        retried: list[SpectrumJob] = []

        def retry(j: Job) -> None:
            if j.status != DONE or self.state.mesh is not j.result:
                return  # failed, cancelled, or another mesh was opened meanwhile
            self.sliver_failure = None
            self.events.info.emit(
                "Slivers fixed", f"{j.result.report}\n\nComputing {key.describe()} again..."
            )
            settings = self.state.compute_settings  # the Compute panel shows what is retried
            settings.operator, settings.k = key.operator, key.k
            job_ = self._request(key.operator, key.k, show=True)
            if job_ is not None:
                retried.append(job_)

        job.then(retry)
        if not wait:
            return job
        self.wait_for(job)
        if job.status != DONE or not retried:
            raise ComputeError(job.error or self.last_error or job.status)
        return self._finish(retried[0], wait=True)

    # ============================================================= spectra
    @property
    def spectra(self) -> dict[str, Spectrum]:
        """The latest spectrum of each computed operator."""
        return {op: self._public(self.state.spectrum(op)) for op in self.state.operators_computed()}

    def spectrum_shown(self) -> Spectrum | None:
        """The spectrum the picture is made of, else the current one (File > Export spectrum)."""
        operators = (self.state.display_operator(), self.state.current_operator())
        shown = [self.state.spectrum(op) for op in operators if op is not None]
        return self._public(next((spec for spec in shown if spec is not None), None))

    def add_spectrum(self, spectrum: Spectrum) -> None:
        """Put a spectrum of the loaded mesh computed elsewhere into the viewer, under the
        current compute settings' key for its operator and k."""
        key = self.state.compute_settings.key(spectrum.operator, spectrum.k)
        self.state.add_spectrum(key, spectrum)

    def compute(
        self, operator: str | None = None, k: int | None = None, wait: bool = True, then=None
    ) -> Spectrum | None:
        """Compute a spectrum in the background (cached on disk) and show its first
        non-zero mode when it arrives (unless the display changed meanwhile).
        ``operator`` and ``k`` default to the compute settings'; ``then`` is called with
        the spectrum.  With ``wait`` returns it, and raises ComputeError if no mesh is
        open or the computation failed, was cancelled or was too large to start."""
        if self.state.mesh is None:
            self.report_error("Open a mesh first.")
            if wait:
                raise ComputeError("Open a mesh first.")
            return None
        if operator is not None:
            self.state.compute_settings.operator = operator
        if k is not None:
            self.state.compute_settings.k = k
        job = self._request(None, None, show=True)
        if job is None and wait:
            raise ComputeError(self.last_error or "the computation was refused")
        return self._finish(job, wait, then)

    def _request(self, operator, k=None, show: bool = False) -> SpectrumJob | None:
        """:meth:`request_spectrum`, said on the status line; None if refused (reported)."""
        try:
            job = self.request_spectrum(operator, k, show=show)
        except ComputeRefused as exc:
            self.report_error(str(exc), "Computation too large")
            return None
        if job.status == DONE:  # answered at once: the spectrum is here already
            self._status(f"{job.description}: already computed.", 8000)
            return job
        note = self.long_wait_note(job)
        if note:
            job.said.append(f"{job.description}: {note}.")
            self._status(job.said[-1], 20000)
        return job

    def modes_ready(self, operator: str | None = None) -> tuple[int, int]:
        """(modes in, modes asked for) of ``operator``'s spectrum (default: the current
        one), e.g. ``(12, 100)`` while modes arrive; in a script it first takes in what
        the computation has handed over."""
        if isinstance(self.jobs.dispatch, ManualDispatcher):
            self.jobs.dispatch.process()
        return self.state.modes_ready(operator or self.state.current_operator())

    def wait_for_modes(
        self, count: int, operator: str | None = None, timeout: float | None = None
    ) -> tuple[int, int]:
        """Wait until ``count`` modes of ``operator``'s spectrum (default: the last asked
        for) are in, or its computation ended; returns :meth:`modes_ready`.  After
        ``compute(..., wait=False)``: the first modes, while the others converge."""
        if not isinstance(self.jobs.dispatch, ManualDispatcher):
            raise RuntimeError(
                "wait_for_modes is for scripts; in a window the modes arrive through the "
                "event loop: connect to viewer.state.events.spectra instead"
            )
        operator = operator or self.state.compute_settings.operator  # the last requested
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            ready, asked = self.modes_ready(operator)
            if (asked and ready >= min(count, asked)) or not self.computing(operator):
                return self.modes_ready(operator)
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"fewer than {count} modes arrived within {timeout} s")
            self.jobs.dispatch.process(timeout=0.05)

    def _finish(self, job: SpectrumJob | None, wait: bool, then=None) -> Spectrum | None:
        if job is None:
            return None
        if then is not None:
            job.then(lambda j: then(self._public(j.result[0])) if j.status == DONE else None)
        return self._public(self._waited(job).result[0]) if wait else None

    def _waited(self, job: Job) -> Job:
        """``job`` once it has ended; ComputeError if it failed or was cancelled."""
        self.wait_for(job)
        if job.status != DONE:
            raise ComputeError(job.error or job.status)
        return job

    def long_wait_note(self, job: SpectrumJob) -> str:
        """ "this will take about ..." for a request expected (from this machine's solves)
        to take longer than :data:`LONG_WAIT_SECONDS`; else ""."""
        seconds = None if job.done else self.estimated_seconds(job.spectrum_key)
        if seconds is None or seconds <= LONG_WAIT_SECONDS:
            return ""
        about = seconds_text(seconds)
        faster = "" if job.spectrum_key.coarse else "; Coarse-to-fine is much faster"
        return f"this will take about {about} (Esc cancels{faster})"

    def cancel_computation(self) -> None:
        """Cancel the running computation (and the other jobs of its spectrum); other
        queued requests keep their turn."""
        running = self.jobs.running
        if running is None:
            self._status("No computation running.", 3000)
            return
        key = running.spectrum_key if isinstance(running, SpectrumJob) else None
        for job in list(self.jobs.jobs):
            if job is running or (isinstance(job, SpectrumJob) and job.spectrum_key == key):
                self.jobs.cancel(job)
        left = {
            job.spectrum_key if isinstance(job, SpectrumJob) else job.key
            for job in self.jobs.jobs
            if not job.done and not job.cancel_requested
        }
        more = _plural(len(left), "more request")
        self._cancel_note = f"Cancelled; {more} queued (Ctrl+Shift+Esc cancels all)" if left else ""
        self._status(self._cancel_note or "Cancelling...", 5000)

    def clear_cache(self) -> int:
        """Delete every cached spectrum; returns the bytes freed."""
        size = self.cache.clear()
        self._status(f"Cache cleared: {size / 2**20:.0f} MB freed.", 8000)
        return size

    def _on_job_changed(self, job: Job) -> None:
        running = self.jobs.running
        if running is not None and job is running and job.stage == "starting":
            # "Computing ..."; after a cancel that left requests queued, first that
            message = f"Computing {job.description}..."
            if self._cancel_note:
                message, self._cancel_note = f"{self._cancel_note}. {message}", ""
            if message not in job.said:  # "starting" may be reported more than once
                job.said.insert(0, message)
            self._status(message)

    def _on_job_finished(self, job: Job) -> None:
        if job.status == DONE and isinstance(job, SpectrumJob):
            spec = job.result[0]
            # the disk note next to the time it explains: the status bar cuts long lines
            text = f"{finished_text(job, spec)}{memory_text(spec)}; {residual_text(spec)}."
            self._status(text, 15000)
        elif job.status == DONE and not isinstance(job, RepairJob):
            self._status(f"{job.description}: done in {job.seconds:.1f} s.", 15000)
        elif job.status == FAILED:
            if job.details:  # an unexpected fault: its traceback for the log
                log.error("computation failed: %s\n%s", job.error, job.details)
            # every failure's message is logged once below, as the user is told it
            mesh = self.state.mesh
            if isinstance(job, RepairJob):
                self.report_error(f"{job.description} failed: {job.error}", "Repair failed")
            elif (
                isinstance(job, SpectrumJob)
                and mesh is not None
                and job.owner == mesh.hash
                and repair_for_failure(job.error) == "fix_slivers"
            ):
                self.sliver_failure = job.spectrum_key
                self.last_error = f"The computation failed: {job.error}"
                log.warning("%s", self.last_error)
                self.events.sliver_failure.emit(job.spectrum_key, self.last_error)
            else:
                self.report_error(f"The computation failed: {job.error}", "Computation failed")
        elif job.status == CANCELLED:
            self._status(f"{ended_text(job)}.", 5000)

    # =============================================================== modes
    def show_mode(self, index: int, operator: str | None = None) -> None:
        """Show mode ``index`` of ``operator`` (default: the current spectrum's)."""
        op = operator or self.state.current_operator()
        if op is None or self.state.spectrum(op) is None:
            return
        self.state.show_mode(index, op)

    def step_mode(self, step: int) -> None:
        """The next (``step`` = 1) or previous (-1) mode of the current spectrum."""
        d = self.state.display
        op = self.state.current_operator()
        if op is None:
            return
        self.state.show_mode((d.mode if d.kind == "mode" and d.operator == op else 0) + step, op)

    def show_current_mode(self, operator: str | None = None) -> None:
        """Back to the mode last shown of ``operator`` (default: the current spectrum's),
        or its first non-zero mode."""
        d = self.state.display
        op = operator or self.state.current_operator()
        if op is not None:
            mode = d.mode if op == d.operator else self.state.first_nonzero_mode(op)
            self.show_mode(mode, op)

    # ======================================================== picks, maps
    @property
    def picked(self) -> int | None:
        """The picked vertex (the input's number, as :attr:`mesh` numbers it), or None."""
        return self.state.picked_file_vertex

    def pick_vertex(self, index: int, show: bool = True) -> None:
        """Pick vertex ``index`` of :attr:`mesh` (the input's numbering; ValueError for
        one no face uses) and, with ``show``, show the distance map of the display's kind
        (computing its spectrum if missing)."""
        if self.state.mesh is None:
            return
        self.state.set_pick_file_vertex(index)
        if show:
            self.show_distance()

    def show_distance(
        self,
        kind: str | None = None,
        display: str | None = None,
        share: float | None = None,
        threshold: float | None = None,
    ) -> np.ndarray | None:
        """Show the distance map of ``kind`` (default: the display's) from the picked
        vertex; a missing spectrum is computed and the map appears when it is ready
        (unless the display changed meanwhile).  ``display``: "continuous" or
        "threshold"; ``share`` (0..1] of the area, or an absolute ``threshold``
        distance, for a threshold map.  Returns the (n,) distances, None until ready or
        without a pick.  ValueError for both share and threshold, a share outside (0, 1],
        a negative threshold or an unknown kind."""
        if share is not None and threshold is not None:
            raise ValueError("give either share (of the area) or threshold (a distance)")
        if share is not None and not 0.0 < float(share) <= 1.0:
            raise ValueError(f"share is a share of the surface's area, in (0, 1]: {share}")
        if threshold is not None and not 0.0 <= float(threshold) < np.inf:
            raise ValueError(f"threshold is a distance, at least 0: {threshold}")
        if kind is not None and kind not in DISTANCE_KINDS:
            raise ValueError(f"unknown distance {kind!r}; choose one of {list(DISTANCE_KINDS)}")
        if display is None and (share is not None or threshold is not None):
            display = "threshold"
        changes = {"distance_kind": kind, "distance_display": display}
        changes = {name: value for name, value in changes.items() if value is not None}
        if changes:
            self.state.set_display(**changes)
        if self.state.mesh is None:
            return None
        if self.state.picked is None:
            if share is not None:  # the first map will mark it
                self.state.set_display(threshold_share=float(share), keep_share=True)
            self._status("Click the surface to pick a vertex first.", 5000)
            return None
        kind = self.state.display.distance_kind
        operator = operator_for_distance(kind)
        if self.state.spectrum(operator) is None:
            job = self._request(operator, None, show=False)
            if job is not None:
                before = self.state.display

                def show_when_ready(j: Job) -> None:
                    if j.status == DONE and self.state.display == before:
                        self._show_map(share, threshold)

                job.then(show_when_ready)
                note = self.long_wait_note(job)
                self._status(
                    f"Computing the spectrum for the {DISTANCE_KINDS[kind].lower()}"
                    + (f"; {note}." if note else "...")
                )
            return None
        return self._show_map(share, threshold)

    def _show_map(self, share: float | None, threshold: float | None) -> np.ndarray | None:
        """Show the display kind's distance map, at ``share`` or ``threshold`` if given."""
        changes: dict = {"kind": "distance"}
        d = self.state.derived.distance_map()
        if threshold is not None and d is not None:
            changes["threshold"] = min(1.0, float(threshold) / (float(d.max()) or 1.0))
        if share is not None:
            changes.update(threshold_share=float(share), keep_share=True)
        self.state.set_display(**changes)
        return self.state.derived.distance_map()

    def distance_map(self, kind: str | None = None) -> np.ndarray | None:
        """Distance of ``kind`` (default: the display's) from the picked vertex, per vertex
        of :attr:`mesh` (NaN where no face uses one); None if its spectrum is missing."""
        return self._input_field(self.state.derived.distance_map(kind))

    def _input_field(self, values: np.ndarray | None) -> np.ndarray | None:
        """Per-vertex ``values`` of the solver's mesh in the input's numbering."""
        if values is None or self.state.mesh is None:
            return values
        return self.state.mesh.to_file_field(values)

    def set_threshold(self, fraction: float) -> float:
        """Move the threshold (a fraction of the largest distance); returns the seconds taken."""
        started = time.perf_counter()
        self.state.set_display(threshold=float(fraction))
        return time.perf_counter() - started

    def show_signature(self, sample: int) -> None:
        """Colour by the signature at scale sample ``sample`` of the distance kind."""
        operator = operator_for_distance(self.state.display.distance_kind)
        if not self.state.derived.has_signatures(operator):
            label = OPERATOR_INFO[operator].label
            self._status(f"Compute the {label} spectrum first (with non-zero modes).", 5000)
            return
        self.state.set_display(kind="signature", signature_sample=int(sample))

    def show_signature_at(self, t: float) -> None:
        """Colour by the signature summed at scale ``t`` itself (not the nearest sample)."""
        operator = operator_for_distance(self.state.display.distance_kind)
        if not self.state.derived.has_signatures(operator):
            self.show_signature(0)  # says what to compute
            return
        t = float(t)
        self.state.set_display(
            kind="signature",
            signature_sample=self.state.derived.nearest_sample(t),
            signature_time=t,
        )

    def show_field(self, name: str, values=None) -> None:
        """Colour by your own per-vertex field ``name``: ``values`` (n,) kept as it
        (:meth:`~.state.ViewerState.add_field`), or one given before.  Signed values get
        the modes' colours, others white to red."""
        if values is not None:
            self.state.add_field(name, values)
        self.state.set_display(kind="field", field=str(name))

    def show_curvature(self) -> None:
        """Colour by the total curvature."""
        if self.state.mesh is not None:
            self.state.set_display(kind="curvature")

    # ============================================================ closing
    def close(self) -> None:
        """Cancel the jobs and free the off-screen renderer."""
        self.jobs.cancel_all(reason="the viewer was closed")
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ============================================================ sessions
    def save_session(self, path) -> Path:
        """Write the session (mesh, spectra, display, pick, camera) to a JSON file."""
        camera = self.current_camera()
        if camera is not None:
            with self.state.events.camera.blocked():  # what the picture shows already
                self.state.camera = camera
        return save_session(self.state, path)

    def open_session(self, path, wait: bool = True) -> list[str]:
        """Restore a session (with ``wait``, its spectra too); returns notes on what could
        not be restored as saved.  SessionError, MeshError or OSError for a bad file."""
        restored = restore_session(self, path)
        if wait:
            for job in restored.jobs:
                self.wait_for(job)
        if restored.notes:
            self._status("; ".join(restored.notes), 15000)
        return restored.notes

    # ========================================================== comparison
    def missing_for(self, items: list[str]) -> list[str]:
        """The operators a comparison of ``items`` needs whose spectra are missing."""
        needed = [operator_for_distance(i) if i in DISTANCE_KINDS else i for i in items]
        return [op for op in dict.fromkeys(needed) if self.state.spectrum(op) is None]

    def comparison_cost(self, operators: list[str]) -> float | None:
        """Seconds the spectra of ``operators`` are expected to take; None if one has no
        estimate."""
        settings = self.state.compute_settings
        seconds = [self.estimated_seconds(settings.key(op)) for op in operators]
        return None if any(s is None for s in seconds) else sum(seconds)

    def prepare_comparison(self, items: list[str], wait: bool = True, then=None):
        """Request the spectra a comparison of ``items`` needs; with ``wait`` return the
        jobs once they are in (ComputeError if one failed), else call ``then()`` then.
        None if a request was refused."""
        jobs = [self._request(op, None, show=False) for op in self.missing_for(items)]
        if any(job is None for job in jobs):
            if wait:
                raise ComputeRefused(self.last_error or "the computation was refused")
            return None
        if wait:
            return [self._waited(job) for job in jobs]
        called = []

        def ready(_job=None) -> None:  # once, when the last job is in (never if one failed)
            if then is not None and not called and all(j.status == DONE for j in jobs):
                called.append(True)
                then()

        for job in jobs:
            job.then(ready)
        if not jobs:
            ready()
        return jobs

    def comparison(self, items: list[str], wait: bool = True):
        """A :class:`~.comparison.Comparison` of two or three operators or distance kinds;
        missing spectra are computed first (the display is not changed)."""
        if self.state.mesh is None:
            raise ComputeError("Open a mesh first.")
        comparison = Comparison(self.state, items)
        self.prepare_comparison(items, wait=wait)
        return comparison

    # ========================================================== shape pair
    def pair(self, mesh_b, k: int | None = None, wait: bool = True, strict: bool = True, path=None):
        """A :class:`~.pair.PairState`: this viewer's mesh as A, ``mesh_b`` (a Mesh or its
        file; ``path`` names a given Mesh's file) as B, with this viewer's distance kind
        and Discrete Shells weights; use ``pair.pick("a", v)``, ``pair.distance_on("b")``
        and ``pair.best_match()`` (the input's numbering).  ``k`` modes per spectrum
        (default: :func:`~modalviewer.core.operators.default_k`); ``strict`` as for
        :meth:`open_mesh`.  ComputeError if no mesh is open, or (with ``wait``, which
        waits for both spectra) a spectrum could not be computed."""
        from ..io import load_mesh

        state = self.state
        if state.mesh is None:
            raise ComputeError("Open a mesh first (it becomes mesh A).")
        path_b = Path(path) if path is not None else None
        if not isinstance(mesh_b, Mesh):
            path_b = Path(mesh_b)
            mesh_b = load_mesh(path_b, strict=strict)
        settings = state.compute_settings
        pair = PairState(
            self.jobs,
            self.cache,
            state.mesh,
            mesh_b,
            state.mesh_path,
            path_b,
            state_a=state,
            k=k,
            weights=(settings.bending, settings.membrane),
            kind=state.display.distance_kind,
        )
        if wait:
            self.wait_for_pair(pair)
        return pair

    def wait_for_pair(self, pair) -> None:
        """Request and wait for ``pair``'s spectra (ComputeError if one failed)."""
        for job in pair.request():
            self.wait_for(job)
            if job.status != DONE:
                raise ComputeError(pair.failure() or job.error or job.status)
        if not pair.ready():
            raise ComputeError(pair.failure() or "the spectra are not in")
