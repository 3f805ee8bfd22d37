"""The viewer's model: its state, the jobs that fill it, and the spectrum cache (no Qt).

:class:`ViewerModel` is what the window, the CLI, the figures and scripts drive.  It
turns a request ("the shells spectrum, 100 modes") into a :class:`~.jobs.Job` whose
result lands in :class:`~.state.ViewerState` when it ends, if the mesh it was computed
for is still the loaded one.  A finished job changes what is displayed only if it was
asked to (``show=True``) and the display has not changed since the request.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..coarsen import COARSE_FRACTION
from ..core.cache import SpectrumCache
from ..core.cost import LAWS_FROM_VERTICES
from ..core.eigen import Cancelled
from ..core.memory import physical_memory_mb
from ..core.mesh import Mesh
from ..core.operators import operator_info
from ..core.pipeline import FLOOR_FACTOR, compute_spectrum
from ..core.preview import preview_possible_on
from ..core.signatures import SignatureTable
from ..core.spectrum import Spectrum
from ..repair import REPAIRS
from .jobs import CANCELLED, DONE, Job, JobQueue, RepairJob, SpectrumJob
from .process import repair_in_process
from .state import SpectrumKey, ViewerState

PROCESS_THRESHOLD = 20000
"""Exact spectra of at least this many unknowns are computed in a separate process
(sparse factorisations hold the GIL; a process also cancels at once); previews always
are (:func:`_compute_preview`)."""

PREVIEW_DELAY = 0.10
"""A preview is computed first only where it is predicted to make the exact spectrum
arrive at most this share later than without it (:func:`preview_plan`)."""


PREVIEW_MARGIN = 2.2
"""A preview comes first only where this many times its predicted time fits within
:data:`PREVIEW_DELAY` of the exact solve's predicted time: the growth laws are fitted
on plates, and on the curved benchmark meshes of 100k to 270k vertices a fast preview's
share of the exact time was up to 2.01 times the share the laws predict (Cheburashka
Loop x2's 3D shells: the preview, with its guard modes, took 0.44 of the exact time,
the laws say 0.22; 0.42 and 0.37 in earlier runs without them;
``benchmarks/results/curved.json``, which ``tests/viewer/test_state_model.py`` checks
the margin against), and a preview that runs past its share is thrown away
(:attr:`PreviewPlan.deadline`)."""


NOTE_FROM_SECONDS = 10.0
"""Requests whose exact solve is predicted to take at least this long say why they get no
preview (quicker ones would only add noise to the status line)."""


@dataclass(frozen=True)
class PreviewPlan:
    """Whether a request gets a preview first, and the predictions behind it
    (:func:`preview_plan`)."""

    pays: bool
    preview_seconds: float
    exact_seconds: float
    preview_mb: float
    exact_mb: float
    n_vertices: int = LAWS_FROM_VERTICES

    @property
    def deadline(self) -> float:
        """Seconds after which a running preview is given up: its share of the exact
        solve's predicted time (:data:`PREVIEW_DELAY`), so a misprediction cannot delay
        the exact spectrum by more."""
        return PREVIEW_DELAY * self.exact_seconds

    def reason(self) -> str:
        """Why there is no preview, in words ("" where there is one)."""
        if self.pays:
            return ""
        if self.n_vertices < LAWS_FROM_VERTICES:
            # only requests predicted to take NOTE_FROM_SECONDS or more are told why, so
            # the exact solve is not "quick" here: the reason is the preview's fixed costs
            return (
                f"no preview below {LAWS_FROM_VERTICES:,} vertices".replace(",", "\u00a0")
                + f" (the exact solve: about {_seconds(self.exact_seconds)}): there a "
                "preview's fixed costs take too large a share of the exact time"
            )
        share = PREVIEW_DELAY * self.exact_seconds
        if PREVIEW_MARGIN * self.preview_seconds > share:
            predicted = (
                f"no preview: predicted {_seconds(self.preview_seconds)} against the exact "
                f"{_seconds(self.exact_seconds)}, "
            )
            if self.preview_seconds > share:
                why = (
                    f"it would delay the exact spectrum by more than {round(100 * PREVIEW_DELAY)} %"
                )
            else:
                why = (
                    f"too close to its {round(100 * PREVIEW_DELAY)} % share (on curved meshes "
                    f"a preview's share is up to {PREVIEW_MARGIN:g} times the predicted one)"
                )
            return predicted + why
        return (
            f"no preview: it would need about {_megabytes(self.preview_mb)}, more than the "
            f"exact solve's {_megabytes(self.exact_mb)}"
        )


def _megabytes(value: float) -> str:
    return f"{value:,.0f}".replace(",", "\u00a0") + "\u00a0MB"


def _seconds(value: float) -> str:
    """Seconds in words: a decimal below 10 s ("9.9 s"), none from there ("10 s")."""
    return f"{value:.0f}\u00a0s" if round(value, 1) >= 10 else f"{value:.1f}\u00a0s"


def preview_plan(key: SpectrumKey, n_vertices: int) -> PreviewPlan:
    """Predict the fast preview's and the exact solve's time and memory for ``key`` on a
    mesh of ``n_vertices``
    (:meth:`~modalviewer.core.operators.OperatorInfo.predicted_seconds`); a preview
    pays when :data:`PREVIEW_MARGIN` times its predicted time is at most
    :data:`PREVIEW_DELAY` of the exact time and it needs no more memory than the exact
    solve, on meshes of at least
    :data:`~modalviewer.core.cost.LAWS_FROM_VERTICES` vertices, where the laws were
    measured (below, fixed costs make a preview take a larger share)."""
    info, k = operator_info(key.operator), key.k
    preview_s = info.predicted_seconds("fast preview", n_vertices, k)
    exact_s = info.predicted_seconds("exact", n_vertices, k)
    preview_mb = info.predicted_peak_mb("fast preview", n_vertices, k)
    exact_mb = info.predicted_peak_mb("exact", n_vertices, k)
    pays = (
        n_vertices >= LAWS_FROM_VERTICES
        and PREVIEW_MARGIN * preview_s <= PREVIEW_DELAY * exact_s
        and preview_mb <= exact_mb
    )
    return PreviewPlan(pays, preview_s, exact_s, preview_mb, exact_mb, n_vertices)


class ComputeRefused(ValueError):
    """A computation was refused before it started; the message says why and what to do."""


def physical_memory() -> int:
    """Bytes of physical memory, or 0 if unknown (:func:`.core.memory.physical_memory_mb`)."""
    megabytes = physical_memory_mb()
    return 0 if megabytes is None else int(megabytes * 2**20)


def copy_vertices(n_vertices: int) -> int:
    """Vertices of the decimated copy Coarse-to-fine solves on (:data:`COARSE_FRACTION`)."""
    return round(COARSE_FRACTION * n_vertices)


def solved_vertices(key: SpectrumKey, n_vertices: int) -> int:
    """Vertices the computation of ``key`` solves on: the mesh's, or with Coarse-to-fine
    its decimated copy's."""
    return copy_vertices(n_vertices) if key.coarse else n_vertices


def memory_needed(key: SpectrumKey, n_vertices: int) -> float:
    """Bytes the exact computation of ``key`` on ``n_vertices`` is predicted to need at
    its peak (:meth:`~modalviewer.core.operators.OperatorInfo.predicted_peak_mb`;
    Coarse-to-fine solves on its decimated copy)."""
    info = operator_info(key.operator)
    return info.predicted_peak_mb("exact", solved_vertices(key, n_vertices), key.k) * 2**20


def preview_start_note(key: SpectrumKey, n_vertices: int) -> str:
    """What the status line adds to "Computing preview of ..." for a shown (Preview only)
    preview of ``key``: how the 3D shells' starts (from a coarse copy of the mesh, or
    from its smooth space and why), and where the exact solve is predicted to be quick
    (below :data:`NOTE_FROM_SECONDS`) that it would take about as long; "" otherwise."""
    from ..coarsen import preview_copy_refusal

    note = ""
    if operator_info(key.operator).preview.factor_step:
        refusal = preview_copy_refusal(n_vertices, key.operator, key.k)
        start = "a coarse copy of the mesh" if refusal is None else f"its smooth space ({refusal})"
        note = f", from {start}"
    exact = predicted_seconds(key, n_vertices)
    if exact < NOTE_FROM_SECONDS:
        note += f"; the exact spectrum would take about {max(exact, 1.0):.0f} s here"
    return note


def predicted_seconds(key: SpectrumKey, n_vertices: int, accuracy: str = "exact") -> float:
    """Seconds the computation of ``key`` ("exact" or "fast preview") on ``n_vertices``
    is predicted to take (the operator's growth laws; Coarse-to-fine solves on its
    decimated copy)."""
    n_solved = solved_vertices(key, n_vertices)
    return operator_info(key.operator).predicted_seconds(accuracy, n_solved, key.k)


MEMORY_SHARE = 0.75
"""Computations expected to need more than this share of the physical memory are refused
before they start."""


def largest_k_that_fits(key: SpectrumKey, n_vertices: int, available: int) -> int:
    """The most modes of ``key``'s operator (its other settings kept) whose expected memory
    stays within :data:`MEMORY_SHARE` of ``available`` bytes; 0 if not even one does."""
    limit = MEMORY_SHARE * available
    lo, hi = 0, max(1, key.k)
    while lo < hi:  # the memory estimate grows with k
        mid = (lo + hi + 1) // 2
        if memory_needed(replace(key, k=mid), n_vertices) <= limit:
            lo = mid
        else:
            hi = mid - 1
    return lo


COARSE_WORDS = "with Coarse-to-fine (a decimated copy)"
"""How :func:`what_fits` names Coarse-to-fine (the viewer's option)."""


PREVIEW_WORDS = "as a preview (Preview only)"
"""How :func:`what_fits` names a preview without the exact spectrum (the viewer's option)."""


def preview_fits(key: SpectrumKey, n_vertices: int, available: int) -> bool:
    """Whether the fast preview of ``key`` is predicted to need at most
    :data:`MEMORY_SHARE` of ``available`` bytes (its growth law, measured at 100 modes,
    plus the arrays each further mode adds:
    :meth:`~modalviewer.core.operators.OperatorInfo.predicted_peak_mb`)."""
    info = operator_info(key.operator)
    needed = info.predicted_peak_mb("fast preview", n_vertices, key.k) * 2**20
    return needed <= MEMORY_SHARE * available


def what_fits(
    key: SpectrumKey,
    n_vertices: int,
    available: int,
    coarse: str = COARSE_WORDS,
    preview: str = PREVIEW_WORDS,
) -> str:
    """What would fit instead of ``key``: fewer modes, Coarse-to-fine (named ``coarse``),
    a preview without the exact spectrum (named ``preview``), or none of them.  The two
    others only where they give ``key.k`` modes: the decimated copy has as many modes as
    unknowns, and a preview needs a reduced space of 3 k functions."""
    k = largest_k_that_fits(key, n_vertices, available)
    copy_modes = operator_info(key.operator).unknowns(copy_vertices(n_vertices))
    coarse_needs = memory_needed(replace(key, coarse=True), n_vertices)
    coarse_fits = (
        not key.coarse and key.k <= copy_modes and coarse_needs <= MEMORY_SHARE * available
    )
    options = []
    if k >= 1:
        options.append(f"at most {k} modes fit")
    if coarse_fits:
        options.append(f"{key.k} modes {coarse} fit")
    if (
        not key.coarse
        and preview_possible_on(n_vertices, key.operator, key.k)
        and preview_fits(key, n_vertices, available)
    ):
        options.append(f"{key.k} modes {preview} fit")
    if not options:
        return "Not even one mode fits: use a coarser mesh or a machine with more memory."
    text = "; ".join(options)
    return text[0].upper() + text[1:] + "."


def _share_words(available: int) -> str:
    """The memory a computation may take, in words: "the 17.6 GiB a computation may take
    (three quarters of this machine's 23.5 GiB)"."""
    share = {0.75: "three quarters", 0.5: "half"}.get(MEMORY_SHARE, f"{MEMORY_SHARE:.0%}")
    return (
        f"the {MEMORY_SHARE * available / 2**30:.1f} GiB a computation may take ({share} of "
        f"this machine's {available / 2**30:.1f} GiB)"
    )


def memory_refusal(
    key: SpectrumKey, n_vertices: int, coarse: str = COARSE_WORDS, preview: str = PREVIEW_WORDS
) -> str | None:
    """A message if computing ``key`` on ``n_vertices`` would need more than
    :data:`MEMORY_SHARE` of this machine's memory, saying what would fit; else None.
    The viewer's refusals and ``modalviewer compute`` say the same."""
    needed = memory_needed(key, n_vertices)
    seconds = predicted_seconds(key, n_vertices)
    available = physical_memory()
    if available and needed > MEMORY_SHARE * available:
        return (
            f"{operator_info(key.operator).label} with {key.k} modes on "
            f"{n_vertices} vertices needs about {needed / 2**30:.1f} GiB of memory "
            f"and {seconds / 60:.0f} min, more than {_share_words(available)}. "
            + what_fits(key, n_vertices, available, coarse, preview)
        )
    return None


def preview_refusal(key: SpectrumKey, n_vertices: int) -> str | None:
    """A message if even the fast preview of ``key`` is predicted to need more than
    :data:`MEMORY_SHARE` of this machine's memory; else None."""
    available = physical_memory()
    if available and not preview_fits(key, n_vertices, available):
        return (
            f"Even a preview of {operator_info(key.operator).label} with {key.k} modes on "
            f"{n_vertices} vertices would need more than {_share_words(available)}: use a "
            "coarser mesh or fewer modes."
        )
    return None


class ViewerModel:
    """State + jobs + cache; every scripted or clicked action of the viewer ends here."""

    def __init__(self, cache: SpectrumCache | None = None, dispatch=None):
        self.state = ViewerState()
        self.derived = self.state.derived  # the values computed from the state
        self.jobs = JobQueue(dispatch)
        self.cache = cache or SpectrumCache()
        self.jobs.events.finished.connect(self._on_job_finished)

    # -------------------------------------------------------------- mesh
    def set_mesh(self, mesh: Mesh, path=None, repairs: list[str] | None = None) -> None:
        """Show ``mesh``: the previous mesh's jobs are cancelled and its spectra dropped."""
        old = self.state.mesh
        if old is not None:
            self.jobs.cancel_all(owner=old.hash, reason="superseded: another mesh was opened")
        self.state.set_mesh(mesh, path, repairs)

    def repair(self, name: str) -> Job:
        """A job applying repair ``name`` (see ``REPAIRS``) to the loaded mesh, in a child
        process (see :mod:`.process`); when it ends the repaired mesh replaces it (its
        report says what changed)."""
        state = self.state
        if state.mesh is None:
            raise ComputeRefused("Open a mesh first.")
        if name not in REPAIRS:
            raise ValueError(f"unknown repair {name!r}; choose one of {', '.join(REPAIRS)}")
        mesh, path, done = state.mesh, state.mesh_path, list(state.mesh_repairs)
        job = self.jobs.add(
            RepairJob(
                lambda progress, cancel: repair_in_process(name, mesh, progress, cancel),
                ("repair", mesh.hash, name),
                REPAIRS[name],
                mesh.hash,
                repair=name,
            )
        )

        def replace_mesh(j: Job) -> None:
            if j.status == DONE and self.state.mesh is mesh:
                self.set_mesh(j.result, path, [*done, name])

        return job.then(replace_mesh)

    def open_mesh(self, path, strict: bool = True) -> Mesh:
        """Load and show a mesh file; raises MeshError or OSError with a user message
        (``strict`` as in :func:`modalviewer.load_mesh`)."""
        from ..io import load_mesh

        mesh = load_mesh(Path(path), strict=strict)
        self.set_mesh(mesh, Path(path))
        return mesh

    # ------------------------------------------------------------ spectra
    def refusal(self, key: SpectrumKey) -> str | None:
        """:func:`memory_refusal` of ``key`` on the loaded mesh."""
        return memory_refusal(key, self.state.mesh.n_vertices)

    def request_spectrum(
        self, operator: str | None = None, k: int | None = None, show: bool = False
    ) -> SpectrumJob:
        """A job computing (or loading from the cache) ``operator``'s spectrum.

        Uses the current compute settings for what is not given.  If the spectrum is
        already in the state, the returned job has ended already.  ``show``: display
        its first non-zero mode when it arrives, unless the display changed meanwhile
        (or, for a spectrum in the state, unless it is the one on screen).
        Raises ComputeRefused if the computation is too large for this machine.
        """
        state = self.state
        if state.mesh is None:
            raise ComputeRefused("Open a mesh first.")
        key = state.compute_settings.key(operator, k)
        display_at_request = state.display
        if state.has_spectrum(key):
            return self._answered(key, show)
        if state.compute_settings.preview_only and not key.coarse and not self._cached(key):
            return self._request_preview_only(key, show, display_at_request)
        refusal = self.refusal(key)
        if refusal:
            raise ComputeRefused(refusal)
        preview = (
            self._add_preview(key, show, display_at_request) if self._wants_preview(key) else None
        )
        work = self._work(key)
        job = self.jobs.add(
            SpectrumJob(work, (state.mesh.hash, key), key.describe(), state.mesh.hash, key, preview)
        )
        # while it runs, behind a preview (this request's, or one kept from an earlier
        # request whose exact computation was cancelled) the exact spectrum follows
        state.set_computing(key, True)
        owner = state.mesh.hash

        def computing_ended(_j: Job) -> None:
            if self.state.mesh is not None and self.state.mesh.hash == owner:
                self.state.set_computing(key, False)

        job.then(computing_ended)
        if show and not self.preview_on_screen(key):
            # behind a preview already on screen the exact spectrum replaces it in place
            # (mode, pick and map stay), as after a preview of this request; a preview
            # held but not shown (another operator on screen) is replaced where it is
            # held, and the exact spectrum is shown as any new one
            job.then(self._shower(key, display_at_request))
        return job

    def preview_on_screen(self, key: SpectrumKey) -> bool:
        """Whether the picture is made of a preview of ``key`` (held from Preview only or
        a cancelled exact computation, not this request's)."""
        held = self.state.spectra.get(key)
        return (
            held is not None and held.is_preview and self.state.display_operator() == key.operator
        )

    def _request_preview_only(self, key: SpectrumKey, show: bool, before) -> SpectrumJob:
        """Preview only (the exact spectrum not in the cache): one preview job and no
        exact computation.  Refined where its
        estimate calls for it if the exact solve's memory would fit (the refinement
        factorises the operator as the exact solve does), the fast preview otherwise;
        shown whatever its estimate (there is nothing better on its way)."""
        if key in self.state.spectra:  # the exact spectrum or a preview of it: either answers
            return self._answered(key, show)
        refusal = preview_refusal(key, self.state.mesh.n_vertices)
        if refusal:
            raise ComputeRefused(refusal)
        accuracy = "preview" if self.refusal(key) is None else "fast preview"
        return self._add_preview(key, show, before, accuracy)

    def _answered(self, key: SpectrumKey, show: bool) -> SpectrumJob:
        """An ended job holding ``key``'s spectrum already in the state; with ``show`` its
        first mode is shown unless that operator is on screen (the mode or map stays)."""
        state = self.state
        spec = state.spectra[key]
        job = SpectrumJob(
            None, key, key.describe(), state.mesh.hash, key, is_preview=spec.is_preview
        )
        job.end_now((spec, None))
        if show and state.display_operator() != key.operator:
            self._show_first_mode(key.operator)
        return job

    def _add_preview(
        self, key: SpectrumKey, show: bool, before, accuracy: str | None = None
    ) -> SpectrumJob:
        """Queue a preview job of ``key`` (``accuracy``: see :meth:`_work`), showing its
        first mode on arrival with ``show`` if the display is still ``before``."""
        state = self.state
        job = self.jobs.add(
            SpectrumJob(
                self._work(key, preview=True, accuracy=accuracy),
                (state.mesh.hash, key, "preview"),
                f"preview of {key.describe()}",
                state.mesh.hash,
                key,
                is_preview=True,
                note="" if accuracy is None else preview_start_note(key, state.mesh.n_vertices),
            )
        )
        if show:
            job.then(self._shower(key, before))
        return job

    def computing(self, operator: str) -> bool:
        """Whether a spectrum of ``operator`` for the loaded mesh is queued or being
        computed (a map waiting for it will follow)."""
        return any(
            isinstance(job, SpectrumJob)
            and not job.done
            and not job.cancel_requested
            and job.spectrum_key.operator == operator
            for job in self.jobs.jobs
        )

    def cancel_running(self) -> None:
        """Cancel the running job and the jobs of the same spectrum request (a preview
        and the exact computation behind it)."""
        running = self.jobs.running
        if running is None:
            return
        key = running.spectrum_key if isinstance(running, SpectrumJob) else None
        for job in list(self.jobs.jobs):
            same = key is not None and isinstance(job, SpectrumJob) and job.spectrum_key == key
            if job is running or same:
                self.jobs.cancel(job)

    def _wants_preview(self, key: SpectrumKey) -> bool:
        """Preview first: asked for, predicted to pay (:func:`preview_plan`), not
        coarse-to-fine, no preview yet, not in the cache."""
        state = self.state
        if not state.compute_settings.preview or key.coarse:
            return False
        if not preview_plan(key, state.mesh.n_vertices).pays:
            return False
        if key in state.spectra:
            return False
        return not self._cached(key)

    def _cached(self, key: SpectrumKey) -> bool:
        """Whether the exact spectrum of ``key`` is in the disk cache."""
        mesh = self.state.compute_mesh(key)
        return self.cache.path(mesh, key.operator, key.k, key.bending, key.membrane).is_file()

    def no_preview_note(self, key: SpectrumKey) -> str:
        """Why a request with "Preview first" on gets no preview ("" where it gets one,
        where none was asked for, or where the exact solve is quick:
        :data:`NOTE_FROM_SECONDS`)."""
        state = self.state
        if not state.compute_settings.preview:
            return ""
        if key.coarse:
            return "no preview with Coarse-to-fine (itself an approximation)"
        plan = preview_plan(key, state.mesh.n_vertices)
        return plan.reason() if plan.exact_seconds >= NOTE_FROM_SECONDS else ""

    def _shower(self, key: SpectrumKey, before):
        """A job callback showing the new spectrum of ``key`` if the display has not
        changed since the request (``before``): at the mode shown then if it was one of
        the same operator's (a new k keeps the user's place; the last mode if there are
        fewer now), else at its first non-zero mode."""

        def show_when_done(j: Job) -> None:
            if (
                j.status == DONE
                and key in self.state.spectra
                and self.state.display in (before, before.blank())
            ):
                if before.kind == "mode" and before.operator == key.operator:
                    self.state.show_mode(before.mode, key.operator)
                else:
                    self._show_first_mode(key.operator)

        return show_when_done

    def _show_first_mode(self, operator: str) -> None:
        self.state.show_mode(self.state.first_nonzero_mode(operator), operator)

    def _work(self, key: SpectrumKey, preview: bool = False, accuracy: str | None = None):
        """The function a job runs for ``key``: cache, compute, signature table (a
        ``preview``: the reduced-space approximation, never cached; ``accuracy`` given:
        Preview only, that accuracy, neither stopped nor discarded)."""
        mesh = self.state.compute_mesh(key)
        cache = self.cache
        t_range = self.state.t_range
        cache_args = (mesh, key.operator, key.k, key.bending, key.membrane)
        needs_table = operator_info(key.operator).distance_kind is not None

        first = preview and accuracy is None  # before an exact computation
        deadline = preview_plan(key, mesh.n_vertices).deadline if first else None

        def work(progress, cancel):
            if preview:
                spec = _compute_preview(
                    mesh, key, progress, cancel, deadline, accuracy or "fast preview", first
                )
            else:
                spec = None if key.coarse else cache.get(*cache_args)
            if spec is None:
                spec = _compute(mesh, key, cache, progress, cancel)
            table = None
            if needs_table and (~spec.zero_mode_mask()).any():
                # built here, off the GUI thread: 0.4 s at 130k vertices
                progress("preparing distances", 0.99)
                if cancel():
                    raise Cancelled()
                table = SignatureTable(spec, t_range=t_range)
            return spec, table

        return work

    def _on_job_finished(self, job: Job) -> None:
        mesh = self.state.mesh
        if not isinstance(job, SpectrumJob):
            return
        key = job.spectrum_key
        if job.status != DONE or mesh is None or job.owner != mesh.hash:
            return
        spec, table = job.result
        if not self.state.has_spectrum(key) or self.state.spectra[key] is not spec:
            self.state.add_spectrum(key, spec, table)


def _compute(mesh: Mesh, key: SpectrumKey, cache: SpectrumCache, progress, cancel) -> Spectrum:
    info = operator_info(key.operator)
    weights = (key.bending, key.membrane)
    if key.coarse:
        from ..coarsen import coarse_to_fine_spectrum

        return coarse_to_fine_spectrum(mesh, key.operator, key.k, *weights, progress, cancel)
    if info.unknowns(mesh.n_vertices) >= PROCESS_THRESHOLD:
        from .process import compute_in_process

        target = cache.writable_path(mesh, key.operator, key.k, *weights)
        return compute_in_process(mesh, key.operator, key.k, *weights, target, progress, cancel)
    spec = compute_spectrum(mesh, key.operator, key.k, *weights, progress, cancel)
    cache.put(mesh, spec, key.k, *weights)
    return spec


class PreviewGivenUp(Cancelled):
    """A preview stopped because it would have delayed the exact spectrum too much (its
    message says why); the exact computation behind it goes on."""


def _compute_preview(
    mesh: Mesh,
    key: SpectrumKey,
    progress,
    cancel,
    deadline: float | None = None,
    accuracy: str = "fast preview",
    discard_rough: bool = True,
) -> Spectrum:
    """A preview (by default the fast one, never refined: a refinement costs about half
    the exact solve), always in a child process: the reduced-space work holds the GIL
    long enough to stall the event loop (up to 5.6 s at 130k in a thread, and 2 to 3 s
    in the reduced eigenproblem of the 9k-unknown spot shells, under Xvfb), and Preview
    only computes previews of small meshes too.

    Given up (:class:`PreviewGivenUp`) after ``deadline`` seconds, and (``discard_rough``)
    where the estimated error of the lower half of its non-zero modes is above
    :data:`~modalviewer.core.preview.REFINE_ABOVE`: such a preview misses modes (thin
    parts a smooth space cannot bend), and only a refinement would find them.  The upper
    half may be further off (the 3D shells' correction step preconditions the lowest 60 %
    of the modes): each mode's legend gives its own estimate.
    A shown preview (``discard_rough`` False: Preview only) of the 3D shells starts from
    a coarse copy of the mesh where one can be made (``core.preview``'s coarse start): it
    finds the modes of thin parts that the smooth space misses, at about 0.35 to 0.45 of
    the exact time, where the smooth space's 0.25 to 0.3 would show them far off."""
    from ..core.preview import REFINE_ABOVE

    weights = (key.bending, key.membrane)
    started = time.perf_counter()

    def stop() -> bool:
        if deadline is not None and time.perf_counter() - started > deadline:
            raise PreviewGivenUp(
                f"preview stopped after {_seconds(deadline)} (its share of the exact solve's "
                f"predicted time)"
            )
        return cancel()

    import tempfile

    from . import process

    folder = tempfile.mkdtemp(prefix="modalviewer-preview-")
    target = Path(folder) / "preview.npz"
    try:
        spec = process.compute_in_process(
            mesh,
            key.operator,
            key.k,
            *weights,
            target,
            progress,
            stop,
            accuracy=accuracy,
            coarse_copy=not discard_rough,
        )
    finally:
        target.unlink(missing_ok=True)
        Path(folder).rmdir()
    lowest = spec.estimated_error_of_lowest(0.5)
    if discard_rough and spec.is_preview and lowest > REFINE_ABOVE:
        raise PreviewGivenUp(
            f"preview not shown: the estimated error of its lower half of modes "
            f"({100 * lowest:.0f} %) is above {100 * REFINE_ABOVE:.0f} %, so it may miss modes"
        )
    return spec


def worst_residual(spec: Spectrum) -> float:
    return float(np.max(spec.residuals[~spec.zero_mode_mask()], initial=0.0))


OUT_OF_CORE_WORDS = "factor kept on disk"
"""What a spectrum whose solve kept its factor out of core says of it (the status line
and ``modalviewer compute``)."""

FLOAT32_BASIS_WORDS = "Krylov basis in single precision"
"""What a spectrum whose solve kept its Krylov basis in single precision says of it."""


def finished_text(job: SpectrumJob, spec: Spectrum) -> str:
    """How a finished spectrum job's status line starts: "<description> in 63.2 s", or
    for a spectrum read from the cache "<description> read from the cache in 0.3 s
    (solved earlier in 63.2 s)", so that a cache hit does not read like a fresh solve."""
    fewer = fewer_modes_text(job, spec)
    if not spec.from_cache:
        return f"{job.description}{fewer} in {job.seconds:.1f} s"
    earlier = spec.parameters.get("seconds_total")
    solved = f" (solved earlier in {earlier:.1f} s)" if isinstance(earlier, (int, float)) else ""
    return f"{job.description}{fewer} read from the cache in {job.seconds:.1f} s{solved}"


def fewer_modes_text(job: SpectrumJob, spec: Spectrum) -> str:
    """``" (only 126: all the mesh has)"`` where the spectrum holds fewer modes than the
    job asked for (a mesh has as many modes as unknowns), else ``""``: the description
    names the number asked for."""
    if spec.k >= job.spectrum_key.k:
        return ""
    unknowns = operator_info(spec.operator).unknowns(spec.n_vertices)
    why = ": all the mesh has" if spec.k >= unknowns else ""
    return f" (only {spec.k}{why})"


def ended_text(job: Job) -> str:
    """How ``job`` ended, in a line: "<description> in 5.6 s" (:func:`finished_text` for
    a spectrum), "<description>: cancelled" (or why it was given up) or
    "<description>: failed"."""
    if job.status == DONE:
        if isinstance(job, SpectrumJob) and job.result:
            return finished_text(job, job.result[0])
        return f"{job.description} in {job.seconds:.1f} s"
    if job.status == CANCELLED:
        return f"{job.description}: {job.error or 'cancelled'}"
    return f"{job.description}: failed"


def memory_text(spec: Spectrum) -> str:
    """``"; ... (memory limit)"`` with :data:`OUT_OF_CORE_WORDS` where the exact solve
    kept its factor out of core (the reason it took longer) and
    :data:`FLOAT32_BASIS_WORDS` where it kept its basis in single precision (the reason
    its residuals are about 1e-7), else ``""``."""
    said = [
        words
        for words, key in ((OUT_OF_CORE_WORDS, "factor_out_of_core"),
                           (FLOAT32_BASIS_WORDS, "basis_float32"))
        if spec.parameters.get(key)
    ]  # fmt: skip
    return f"; {' and '.join(said)} (memory limit)" if said else ""


def residual_text(spec: Spectrum) -> str:
    """'largest relative residual 1.3e-05' and, where that is above what well-shaped
    meshes reach, the mode's rounding floor: the residual that rounding the mode to
    double precision alone causes on this mesh (an estimate: no solver goes much below
    it)."""
    worst = worst_residual(spec)
    text = f"largest relative residual {worst:.1e}"
    floor = float(spec.parameters.get("worst_residual_rounding_floor", 0.0))
    if floor > 0.0 and worst <= 1.5 * floor:
        # the floor is an estimate, not a bound: the residual may be a little below it
        text += (
            f" (at the rounding floor of double precision for that mode here, about {floor:.1e})"
        )
    elif floor > 0.0 and worst <= FLOOR_FACTOR * floor:
        text += (
            f" ({worst / floor:.0f} times the rounding floor of double precision for that "
            f"mode here, about {floor:.1e}: as close as solvers come)"
        )
    elif floor > 0.0:
        text += f" (rounding floor {floor:.1e})"
    return text
