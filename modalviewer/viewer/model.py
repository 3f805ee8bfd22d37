"""The viewer's model: its state, the jobs that fill it, and the spectrum cache (no Qt).

A request becomes a :class:`~.jobs.Job` whose modes land in the state, as they converge,
while the mesh they were computed for is still loaded; a job changes the display only if
asked (``show=True``) and the display has not changed since the request.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from ..coarsen import COARSE_FRACTION
from ..core.cache import SolveRecord, SpectrumCache
from ..core.eigen import Cancelled
from ..core.local_signature import local_signature
from ..core.memory import memory_refusal
from ..core.mesh import Mesh
from ..core.operators import operator_info
from ..core.signatures import SignatureTable
from ..core.spectrum import Spectrum
from ..repair import REPAIRS
from .jobs import DONE, Job, JobQueue, RepairJob, SpectrumJob
from .process import repair_in_process
from .state import SpectrumKey, ViewerState


class ComputeRefused(ValueError):
    """A computation was refused before it started; the message says why and what to do."""


# how :func:`estimated_seconds` scales a recorded solve (its docstring says when)
ESTIMATE_RANGE = 2.0  # recorded vertex counts and numbers of modes within this factor
SIZE_EXPONENT = 1.2  # seconds grow as the vertex count to this power
MODES_EXPONENT = 0.6  # seconds grow as the number of modes to this power


def estimated_seconds(
    records: list[SolveRecord], operator: str, n_vertices: int, k: int, mesh_hash: str = ""
) -> float | None:
    """Seconds an exact solve of ``k`` modes of ``operator`` on a mesh of ``n_vertices``
    (hash ``mesh_hash``) is expected to take, from this machine's ``records`` (most recent
    first), or None: the same mesh and k; else the same mesh at the nearest k0 within
    :data:`ESTIMATE_RANGE`, scaled by ``(k / k0) ** MODES_EXPONENT``; else the same k on
    the mesh nearest in size n0 within it, scaled by ``(n / n0) ** SIZE_EXPONENT``.  One
    scaling, only that near: the growth depends on the operator and the shape."""
    same = [r for r in records if r.operator == operator]
    n, k = max(int(n_vertices), 1), max(int(k), 1)

    def within(a: float, b: float) -> bool:
        return b / ESTIMATE_RANGE <= a <= ESTIMATE_RANGE * b

    mesh = [r for r in same if mesh_hash and r.mesh_hash == mesh_hash]
    modes = [r for r in mesh if within(r.k, k)]
    if modes:  # the most recent of the nearest k: of k itself if recorded
        best = min(modes, key=lambda r: abs(np.log(r.k / k)))
        return best.seconds * (k / best.k) ** MODES_EXPONENT
    sizes = [r for r in same if r.k == k and within(r.n_vertices, n)]
    if sizes:
        best = min(sizes, key=lambda r: abs(np.log(r.n_vertices / n)))
        return best.seconds * (n / best.n_vertices) ** SIZE_EXPONENT
    return None


def expected_seconds(key: SpectrumKey, mesh: Mesh, cache: SpectrumCache) -> float | None:
    """:func:`estimated_seconds` of ``key`` on ``mesh``; None for Coarse-to-fine (not
    recorded) and for a cached spectrum (nothing is solved)."""
    if key.coarse or key.cached(mesh, cache):
        return None
    return estimated_seconds(cache.solves(), key.operator, mesh.n_vertices, key.k, mesh.hash)


class ViewerModel:
    """The state, the job queue, the spectrum cache and the requests that fill the state
    (:class:`.viewer.Viewer` adds messages and the scripting API)."""

    def __init__(self, cache: SpectrumCache | None = None, dispatch=None, waiter=None):
        self.state = ViewerState()
        self.jobs = JobQueue(dispatch)
        self.cache = cache or SpectrumCache()
        self._waiter = waiter  # how a window waits (Viewer.use_event_loop)
        self.jobs.events.finished.connect(self._store_result)

    def wait_for(self, job: Job, timeout: float | None = None) -> Job:
        """Wait until ``job`` has ended (its callbacks have run)."""
        if job.done:
            return job
        return self._waiter(job) if self._waiter is not None else self.jobs.wait(job, timeout)

    # -------------------------------------------------------------- mesh
    def set_mesh(self, mesh: Mesh, path=None, repairs: list[str] | None = None) -> None:
        """Show ``mesh``: the previous mesh's jobs are cancelled and its spectra dropped."""
        old = self.state.mesh
        if old is not None:
            self.jobs.cancel_all(owner=old.hash, reason="superseded: another mesh was opened")
        self.state.set_mesh(mesh, path, repairs)

    def repair(self, name: str) -> Job:
        """A job applying repair ``name`` (``REPAIRS``) in a child process; the repaired
        mesh replaces the loaded one."""
        state = self.state
        if state.mesh is None:
            raise ComputeRefused("Open a mesh first.")
        if name not in REPAIRS:
            raise ValueError(f"unknown repair {name!r}; choose one of {', '.join(REPAIRS)}")
        mesh, path, done = state.mesh, state.mesh_path, list(state.mesh_repairs)
        work = partial(repair_in_process, name, mesh)  # work(progress, cancel)
        job = self.jobs.add(RepairJob(work, ("repair", mesh.hash, name), REPAIRS[name], mesh.hash))

        def replace_mesh(j: Job) -> None:
            if j.status == DONE and self.state.mesh is mesh:
                self.set_mesh(j.result, path, [*done, name])

        return job.then(replace_mesh)

    def open_mesh(self, path, strict: bool = True) -> Mesh:
        """Load a mesh file (OBJ, PLY, OFF or STL), show it and return it.  A damaged or
        truncated file raises :class:`modalviewer.readers.DamagedFileError` with
        ``strict``, else loads its whole records (the report says what was dropped);
        MeshError for other unusable meshes, OSError if the file cannot be read."""
        from ..io import load_mesh

        mesh = load_mesh(Path(path), strict=strict)
        self.set_mesh(mesh, Path(path))
        return mesh

    # ------------------------------------------------------------ spectra
    def refusal(self, key: SpectrumKey) -> str | None:
        """:func:`~.core.memory.memory_refusal` of ``key`` on the loaded mesh
        (Coarse-to-fine solves on its decimated copy)."""
        info, n = operator_info(key.operator), self.state.mesh.n_vertices
        copy = round(COARSE_FRACTION * n)
        if key.coarse:
            return memory_refusal(info, key.k, copy)
        return memory_refusal(info, key.k, n, copy, "with Coarse-to-fine (a decimated copy)")

    def request_spectrum(
        self, operator: str | None = None, k: int | None = None, show: bool = False, key=None
    ) -> SpectrumJob:
        """A job computing (or loading from the cache) ``operator``'s spectrum, the compute
        settings for what is not given (an ended one if the state has it), or the spectrum
        ``key``; ``show``: show its first non-zero mode when it arrives, unless the display
        changed meanwhile.  ComputeRefused if too large for this machine."""
        state = self.state
        if state.mesh is None:
            raise ComputeRefused("Open a mesh first.")
        key = key or state.compute_settings.key(operator, k)
        display_at_request = state.display
        if state.has_spectrum(key):  # an ended job; shown unless that operator is on screen
            job = SpectrumJob(None, key, key.describe(), state.mesh.hash, key)
            if show and state.display_operator() != key.operator:
                state.show_mode(state.first_nonzero_mode(key.operator), key.operator)
            return job.end_now((state.spectra[key], None))
        refusal = self.refusal(key)
        if refusal:
            raise ComputeRefused(refusal)
        job = self.jobs.add_spectrum(
            lambda on_modes: self._work(key, on_modes),
            (state.mesh.hash, key),
            key.describe(),
            state.mesh.hash,
            key,
            self._modes_arrived(key, display_at_request if show else None),
        )
        state.set_computing(key, True)
        owner = state.mesh.hash

        def ended(j: Job) -> None:
            if self.state.mesh is None or self.state.mesh.hash != owner:
                return
            self.state.set_computing(key, False)
            if show and j.status == DONE and key in self.state.spectra:
                self._show_if_unchanged(key.operator, display_at_request)

        return job.then(ended)

    def _modes_arrived(self, key: SpectrumKey, show_from):
        """Where the modes of ``key`` go as they converge: into the state while its mesh is
        loaded; the first are shown if the display is still ``show_from`` (a ``show``
        request's)."""
        owner = self.state.mesh.hash
        wanted = [show_from]

        def deliver(spec: Spectrum) -> None:
            state = self.state
            if state.mesh is None or state.mesh.hash != owner:
                return
            state.add_spectrum(key, spec)
            before = wanted[0]
            shown = state.spectra.get(key)  # spec, or spec in the solver's numbering
            if before is None or shown is None or shown.k != spec.k:
                return  # not shown (yet): the spectrum on screen has more modes
            if spec.zero_mode_mask().all():
                return
            wanted[0] = None
            self._show_if_unchanged(key.operator, before)

        return deliver

    def computing(self, operator: str) -> bool:
        """Whether a spectrum of ``operator`` is queued or being computed."""
        return any(  # the queue holds only jobs that have not ended
            isinstance(job, SpectrumJob)
            and not job.cancel_requested
            and job.spectrum_key.operator == operator
            for job in self.jobs.jobs
        )

    def estimated_seconds(self, key: SpectrumKey) -> float | None:
        """:func:`expected_seconds` of ``key`` on the loaded mesh (None without one)."""
        if self.state.mesh is None:
            return None
        return expected_seconds(key, self.state.compute_mesh(key), self.cache)

    def _show_if_unchanged(self, operator: str, before) -> None:
        """Show ``operator``'s spectrum if the display is still ``before``: at the mode
        shown then if of this operator (a new k keeps the user's place), else at its
        first non-zero mode."""
        if self.state.display not in (before, before.blank()):
            return
        same = before.kind == "mode" and before.operator == operator
        mode = before.mode if same else self.state.first_nonzero_mode(operator)
        self.state.show_mode(mode, operator)

    def _work(self, key: SpectrumKey, on_modes=None):
        """The function a job runs for ``key``: the spectrum, then its signature table."""
        mesh = self.state.compute_mesh(key)
        cache = self.cache
        t_range = self.state.t_range
        needs_table = operator_info(key.operator).distance_kind is not None

        def work(progress, cancel):
            spec = key.spectrum(mesh, cache, progress, cancel, on_modes)
            table = None
            if needs_table and (~spec.zero_mode_mask()).any():
                # built here, off the GUI thread (on big meshes it takes a moment)
                progress("preparing distances", 0.99)
                if cancel():
                    raise Cancelled()
                table = SignatureTable(spec, t_range=t_range)
            return spec, table

        return work

    def request_exact_curve(self, wait: bool = False) -> Job | None:
        """A job summing the picked vertex's signature curve over all modes
        (:func:`~modalviewer.core.local_signature.local_signature`); the result is
        :meth:`.derived.DerivedValues.exact_curve`, announced by
        ``state.events.signature_curve``.  None without a curve, for a coarse-to-fine
        spectrum, or if it is in already."""
        state, derived = self.state, self.state.derived
        key = derived.curve_key()
        if key is None or derived.exact_curve() is not None:
            return None
        operator, _, vertex, _ = key
        spec = state.spectrum(operator)
        spectrum_key = state.spectrum_key(operator)
        if spectrum_key.coarse:
            return None
        mesh = state.compute_mesh(spectrum_key)
        times = derived.table(operator).times.copy()

        def run(progress, cancel):
            progress("exact signature", 0.0)
            return local_signature(
                mesh,
                operator,
                [vertex],
                times,
                bending=spectrum_key.bending,
                membrane=spectrum_key.membrane,
                spectrum=spec,
            )[0]

        number = state.picked_file_vertex
        job = self.jobs.submit(
            run, ("exact curve", *key), f"exact signature of vertex {number}", owner=state.mesh.hash
        )

        def arrived(j: Job) -> None:
            if j.status == DONE:
                derived.keep_exact_curve(key, j.result)
                state.events.signature_curve.emit()

        job.then(arrived)
        return self.wait_for(job) if wait else job

    def _store_result(self, job: Job) -> None:
        mesh = self.state.mesh
        if not isinstance(job, SpectrumJob):
            return
        key = job.spectrum_key
        if job.status != DONE or mesh is None or job.owner != mesh.hash:
            return
        spec, table = job.result
        if not self.state.has_spectrum(key) or self.state.spectra[key] is not spec:
            self.state.add_spectrum(key, spec, table)
