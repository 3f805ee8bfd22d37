"""Two meshes side by side: a pick on one, the distance between shapes on the other (no Qt).

:class:`PairState` holds meshes A and B, the distance kind and its display, whether both
are rescaled to unit area first (signatures carry a factor 1/area and the shells
spectrum is not scale covariant: :mod:`.core.cross`), and the pick.  Its spectra go
through the main window's :class:`~.jobs.JobQueue` and the disk cache, reusing the main
window's spectrum of A; distances are :class:`~modalviewer.core.cross.CrossTables`
queries.  The window draws :meth:`PairState.view` of each side and observes ``events``:
``meshes()``, ``spectra()``, ``display()`` (also after any setting changed; each
evented field has its own event too), ``linked(on)`` and ``message(str)``.  Vertices
and distances are in the input's numbering; only :class:`PairView` numbers those of
:meth:`PairState.drawn_mesh`.
"""

from __future__ import annotations

import warnings
from dataclasses import InitVar, dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
from psygnal import Signal, SignalGroup, SignalGroupDescriptor

from ..core.cache import SpectrumCache
from ..core.cross import CrossTables, Matches, ScaleWarning
from ..core.laplacian import lumped_masses
from ..core.mesh import Mesh, MeshError
from ..core.operators import (
    DISTANCE_KINDS,
    default_k,
    operator_for_distance,
    operator_info,
    signature_kind,
)
from ..core.spectrum import Spectrum
from ..core.validate import check_vertices
from .color_scale import auto_spread
from .jobs import CANCELLED, DONE, Job, JobQueue
from .model import expected_seconds
from .state import (
    DEFAULT_THRESHOLD_SHARE,
    DISTANCE_DISPLAYS,
    ComputeSettings,
    SpectrumKey,
    ViewerState,
    unit_area,
)
from .wording import arrival_text

SIDES = ("a", "b")


def other(side: str) -> str:
    _check_side(side)
    return "b" if side == "a" else "a"


def _check_side(side: str) -> None:
    if side not in SIDES:
        raise ValueError(f"side must be 'a' or 'b', got {side!r}")


@dataclass
class PairView:
    """What one side of the pair draws, on :meth:`PairState.drawn_mesh` (its numbering)."""

    values: np.ndarray | None  # distances from the pick on the other side
    colormap: str  # "sequential", "threshold" (blue below threshold) or "plain"
    threshold: float | None
    marker: int | None  # the pick (picked side) or the best match (other side)
    back_marker: int | None  # the best match back, when not mutual
    legend: str
    colorbar_title: str | None = None
    colorbar_labels: list[str] | None = None  # a threshold's swatches
    scale: np.ndarray | None = None  # knots spread by area (color_scale.auto_spread)


class PairEvents(SignalGroup):
    meshes = Signal()
    spectra = Signal()
    display = Signal()
    message = Signal(str)


class _Side:
    def __init__(self, mesh: Mesh, path) -> None:
        self.mesh = mesh.solver_mesh  # the vertices faces use; its map gives the input's numbers
        self.name = Path(path).name if path is not None else "mesh"
        self.masses = lumped_masses(self.mesh)
        self.unit_mesh: Mesh | None = None


@dataclass(eq=False)
class PairState:
    """Meshes A and B, their spectra, the pick and the display (module docstring).
    ``state_a``: a viewer state whose spectra of A are reused; ``k``: modes per spectrum
    (default: :func:`~modalviewer.core.operators.default_k`); ``weights``: Discrete
    Shells (bending, membrane); ``share``: of the other mesh's area, marked by the
    threshold display; ``linked``: the two cameras move together."""

    events: ClassVar = SignalGroupDescriptor(
        signal_group_class=PairEvents,
        signal_aliases=dict.fromkeys(("jobs", "cache", "state_a", "weights")),
    )
    jobs: JobQueue
    cache: SpectrumCache
    mesh_a: InitVar[Mesh]
    mesh_b: InitVar[Mesh]
    path_a: InitVar[object] = None
    path_b: InitVar[object] = None
    state_a: ViewerState | None = None
    k: int | None = None
    weights: tuple[float, float] = (1.0, 1.0)
    kind: str = "hks"
    rescale: bool = True
    distance_display: str = "continuous"
    share: float = DEFAULT_THRESHOLD_SHARE
    linked: bool = True

    def __setattr__(self, name: str, value) -> None:
        if name == "kind" and value not in DISTANCE_KINDS:
            raise ValueError(f"distance kind must be one of {', '.join(DISTANCE_KINDS)}")
        if name == "distance_display" and value not in DISTANCE_DISPLAYS:
            raise ValueError(f"display must be one of {DISTANCE_DISPLAYS}")
        if name == "k" and value is not None:
            value = int(value)
            if value < 1:
                raise ValueError("the number of modes must be at least 1")
        elif name == "share":
            if not np.isfinite(value := float(value)):
                raise ValueError("the share must be a number between 0 and 1")
            value = float(np.clip(value, 0.0, 1.0))
        elif name in ("rescale", "linked"):
            value = bool(value)
        elif name == "weights":
            value = (float(value[0]), float(value[1]))
        super().__setattr__(name, value)

    def __post_init__(self, mesh_a: Mesh, mesh_b: Mesh, path_a, path_b) -> None:
        self.sides = {"a": _Side(mesh_a, path_a), "b": _Side(mesh_b, path_b)}
        if self.k is None:
            self.k = min(default_k(self.sides[s].mesh.n_vertices) for s in SIDES)
        for name in ("kind", "k", "rescale", "distance_display", "share"):
            getattr(self.events, name).connect(lambda: self.events.display.emit())
        self._pick: tuple[str, int] | None = None  # (side, vertex of the drawn mesh)
        self.note = ""  # a warning about the current pair (scale), shown in legends
        self._spectra: dict[tuple[str, str, SpectrumKey], Spectrum] = {}
        self._pending: dict[tuple[str, str, SpectrumKey], Job] = {}
        self._failed: dict[tuple[str, str, SpectrumKey], str] = {}
        self._tables: tuple | None = None  # (ids of both spectra, kind; CrossTables or error)
        self._distance: tuple | None = None  # (tables id, pick, distances)
        self._back: tuple | None = None  # (tables id, side, best match, back match)
        self._scale: tuple | None = None  # (distances, their spread colour scale)

    # ----------------------------------------------------------- meshes
    def mesh(self, side: str) -> Mesh:
        """Mesh ``side`` as given (the input's numbering)."""
        return self.drawn_mesh(side).input_mesh

    def drawn_mesh(self, side: str) -> Mesh:
        """The surface drawn of ``side``: the vertices faces use (:class:`PairView`'s)."""
        _check_side(side)
        return self.sides[side].mesh

    def name(self, side: str) -> str:
        _check_side(side)
        return self.sides[side].name

    def set_mesh(self, side: str, mesh: Mesh, path=None) -> None:
        """Replace mesh ``side``, cancelling its jobs and dropping the pick."""
        _check_side(side)
        self.jobs.cancel_all(owner=self.owner(side), reason="superseded: another mesh")
        self.sides[side] = _Side(mesh, path)
        self._pick = None
        self._tables = self._distance = None
        self.events.meshes.emit()
        self.events.display.emit()

    def owner(self, side: str) -> tuple:
        """The owner of this pair's jobs for ``side``."""
        return ("pair", id(self), side, self.sides[side].mesh.hash)

    # ---------------------------------------------------------- settings
    @property
    def operator(self) -> str:
        return operator_for_distance(self.kind)

    def key(self) -> SpectrumKey:
        """The spectrum key both meshes need now, made as the compute settings make one."""
        return ComputeSettings(self.operator, self.k, *self.weights, self.rescale).key()

    def set_display(self, display: str, share: float | None = None) -> None:
        """Set ``distance_display`` and, if given, ``share``."""
        self.distance_display = display
        if share is not None:
            self.share = share

    @property
    def picked(self) -> tuple[str, int] | None:
        """(side, vertex) of the pick, or None."""
        if self._pick is None:
            return None
        side, v = self._pick
        return side, self.sides[side].mesh.file_vertex(v)

    def pick(self, side: str, vertex: int | None) -> None:
        """Pick ``vertex`` of mesh ``side`` (None clears it); ValueError for one no face uses."""
        _check_side(side)
        new = None
        if vertex is not None:
            if isinstance(vertex, bool) or not isinstance(vertex, int | np.integer):
                raise ValueError(f"a vertex is an integer index, got {vertex!r}")
            try:
                new = (side, self.sides[side].mesh.mesh_vertex(int(vertex)))
            except MeshError as exc:
                raise ValueError(f"{side.upper()}: {exc}") from None
        if new != self._pick:
            self._pick = new
            self.events.display.emit()

    # ----------------------------------------------------------- spectra
    def spectrum(self, side: str, key: SpectrumKey | None = None) -> Spectrum | None:
        """The spectrum of ``side`` for ``key`` (default: the current one), if in."""
        _check_side(side)
        key = key or self.key()
        mesh = self.sides[side].mesh
        spec = self._spectra.get((side, mesh.hash, key))
        if spec is None and side == "a" and self.state_a is not None:
            if self.state_a.mesh is not None and self.state_a.mesh.hash == mesh.hash:
                spec = self.state_a.spectra.get(key)
        return spec

    def ready(self) -> bool:
        return all(self.spectrum(s) is not None for s in SIDES)

    def pending(self) -> list[Job]:
        """This pair's jobs that have not ended (queued or running)."""
        return [job for job in self._pending.values() if not job.done]

    def failure(self) -> str | None:
        """Why a spectrum the display needs failed, if one did."""
        key = self.key()
        for side in SIDES:
            error = self._failed.get((side, self.sides[side].mesh.hash, key))
            if error:
                return f"{side.upper()}: {error}"
        return None

    def request(self) -> list[Job]:
        """Request the spectra the current key needs that are not in; returns the jobs
        still pending."""
        key = self.key()
        jobs = []
        for side in SIDES:
            s = self.sides[side]
            slot = (side, s.mesh.hash, key)
            spec = self.spectrum(side)
            if spec is not None and spec.is_complete:
                continue
            job = self._pending.get(slot)
            if job is None or job.done:
                self._failed.pop(slot, None)
                job = self.jobs.add_spectrum(
                    lambda on_modes, side=side: self._work(side, key, on_modes),
                    (s.mesh.hash, key),
                    f"{key.describe()} of {side.upper()} ({s.name})",
                    self.owner(side),
                    key,
                    lambda spec, slot=slot: self._on_job(slot, None, spec),
                )
                self._pending[slot] = job
                job.then(lambda j, slot=slot: self._on_job(slot, j))
            jobs.append(job)
        return [job for job in jobs if not job.done]

    def estimated_seconds(self) -> float | None:
        """Seconds the missing spectra are expected to take; None if none is missing or
        one has no estimate."""
        key = self.key()
        missing = [side for side in SIDES if self.spectrum(side) is None]
        seconds = [expected_seconds(key, self.compute_mesh(s, key), self.cache) for s in missing]
        return None if not missing or None in seconds else sum(seconds)

    def cancel(self) -> None:
        """Cancel this pair's jobs (queued and running)."""
        for side in SIDES:
            self.jobs.cancel_all(owner=self.owner(side), reason="cancelled")

    def compute_mesh(self, side: str, key: SpectrumKey) -> Mesh:
        """The mesh ``side``'s spectrum for ``key`` is computed on (unit area with rescale)."""
        s = self.sides[side]
        if key.rescale and s.unit_mesh is None:
            s.unit_mesh = unit_area(s.mesh)
        return s.unit_mesh if key.rescale else s.mesh

    def _work(self, side: str, key: SpectrumKey, on_modes=None):
        mesh, cache = self.compute_mesh(side, key), self.cache
        return lambda progress, cancel: (
            key.spectrum(mesh, cache, progress, cancel, on_modes),
            None,
        )

    def arrival_note(self) -> str:
        """ "from the first 20 of 100 modes of B" while a spectrum is incomplete, else ""."""
        arriving = {side: arrival_text(self.spectrum(side)) for side in SIDES}
        parts = [f"the {text} of {side.upper()}" for side, text in arriving.items() if text]
        return f"from {' and '.join(parts)}" if parts else ""

    def _on_job(self, slot, job: Job | None, spec: Spectrum | None = None) -> None:
        """``slot``'s ended ``job``, or without one its first modes ``spec`` (the maps are
        made of them until the whole spectrum is in), while its mesh is loaded."""
        side, mesh_hash, key = slot
        if job is not None:
            self._pending.pop(slot, None)
        if mesh_hash != self.sides[side].mesh.hash:
            return
        if job is None or job.status == DONE:
            self._spectra[slot] = spec if job is None else job.result[0]
            self.events.spectra.emit()
        elif job.status == CANCELLED:
            # not a failure: the legend says so, and the next request computes again
            self._failed[slot] = "cancelled; pick again to compute"
        else:
            self._failed[slot] = f"failed: {job.error or 'unknown error'}"
            if key == self.key():
                self.events.message.emit(
                    f"The {key.describe()} of {side.upper()} ({self.name(side)}) could not "
                    f"be computed: {job.error}"
                )
        if key == self.key():
            self.events.display.emit()

    # --------------------------------------------------------- distances
    def _cross_tables(self) -> CrossTables | None:
        """Both signature tables at common scales, or None (``note`` says why if they
        cannot be compared)."""
        sa, sb = self.spectrum("a"), self.spectrum("b")
        if sa is None or sb is None:
            return None
        ids = (id(sa), id(sb), self.kind)  # the heat and wave kernels share a spectrum
        if self._tables is None or self._tables[0] != ids:
            self.note = ""
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always", ScaleWarning)
                    tables = CrossTables(sa, sb, kind=signature_kind(self.kind))
                if any(issubclass(w.category, ScaleWarning) for w in caught):
                    area_a, area_b = (float(s.mass.sum()) for s in (sa, sb))
                    self.note = (
                        f"areas differ ({area_a:.3g} and {area_b:.3g}): tick Rescale to "
                        "compare shapes"
                    )
            except ValueError as exc:
                tables = str(exc)
                self.note = str(exc)
            self._tables = (ids, tables)
        tables = self._tables[1]
        return tables if isinstance(tables, CrossTables) else None

    def _drawn_distance(self, side: str) -> np.ndarray | None:
        """:meth:`distance_on` on the drawn mesh of ``side``."""
        if self._pick is None or self._pick[0] == side:
            return None
        tables = self._cross_tables()
        if tables is None:
            return None
        key = (id(tables), self._pick)
        if self._distance is None or self._distance[0] != key:
            from_side, v = self._pick
            d = tables.a_to_b(v) if from_side == "a" else tables.b_to_a(v)
            self._distance = (key, d)
        return self._distance[1]

    def _spread(self, side: str, d: np.ndarray):
        """:func:`auto_spread` of ``d`` on ``side``, kept while ``d`` is."""
        if self._scale is None or self._scale[0] is not d:
            self._scale = (d, auto_spread(d, self.sides[side].masses))
        return self._scale[1]

    def _drawn_matches(self) -> tuple[str, int, float, int] | None:
        """(side, best match, its distance, match back) on the drawn meshes."""
        d = None if self._pick is None else self._drawn_distance(other(self._pick[0]))
        if d is None:
            return None
        side = other(self._pick[0])
        w = int(np.argmin(d))
        tables = self._cross_tables()
        key = (id(tables), side, w)
        if self._back is None or self._back[0] != key:
            back = tables.a_to_b(w) if side == "a" else tables.b_to_a(w)
            self._back = (key, int(np.argmin(back)))
        return side, w, float(d[w]), self._back[1]

    def distance_on(self, side: str) -> np.ndarray | None:
        """(n,) distance from the pick on the other side to every vertex of ``side`` (NaN
        where no face uses it); None without a pick there or the spectra."""
        _check_side(side)
        d = self._drawn_distance(side)
        return None if d is None else self.sides[side].mesh.to_file_field(d)

    def best_match(self) -> tuple[str, int, float] | None:
        """(side, vertex, distance): the vertex of the other mesh closest to the pick."""
        match = self._drawn_matches()
        if match is None:
            return None
        side, w, distance, _ = match
        return side, self.sides[side].mesh.file_vertex(w), distance

    def back_match(self) -> int | None:
        """The picked mesh's vertex closest to the best match (the pick when mutual)."""
        match = self._drawn_matches()
        if match is None:
            return None
        return self.sides[other(match[0])].mesh.file_vertex(match[3])

    def mutual_best_matches(self, vertices_a, vertices_b=None) -> Matches | None:
        """:meth:`CrossTables.mutual_best_matches` of vertices of A (among vertices of B);
        None if the spectra are not in."""
        tables = self._cross_tables()
        if tables is None:
            return None
        mesh_a, mesh_b = self.sides["a"].mesh, self.sides["b"].mesh
        va = _drawn_vertices(mesh_a, vertices_a, "A")
        vb = None if vertices_b is None else _drawn_vertices(mesh_b, vertices_b, "B")
        m = tables.mutual_best_matches(va, vb)
        back = mesh_a.file_vertices[m.back_matches_a]
        picked = mesh_a.file_vertices[m.vertices_a]
        return Matches(picked, mesh_b.file_vertices[m.matches_b], m.distances, back, m.mutual)

    def threshold(self, side: str) -> tuple[float, float] | None:
        """(t, share covered) of the threshold on ``side``: the smallest t whose set
        ``d <= t`` covers ``share`` of the area, and the share it covers."""
        d = self._drawn_distance(side)
        if d is None:
            return None
        masses = self.sides[side].masses
        order = np.argsort(d, kind="stable")
        covered = np.cumsum(masses[order]) / masses.sum()
        i = int(np.clip(np.searchsorted(covered, self.share - 1e-12), 0, len(d) - 1))
        value = float(d[order[i]])
        return value, float(masses[d <= value].sum() / masses.sum())

    # -------------------------------------------------------------- words
    def _missing(self) -> str:
        failure = self.failure()
        if failure:
            return failure
        spectra = [(s.upper(), self.spectrum(s)) for s in SIDES]  # first modes: still computing
        waiting = [s for s, spec in spectra if spec is None or not spec.is_complete]
        if waiting:
            label = operator_info(self.operator).label
            return f"computing the {label} spectrum of {' and '.join(waiting)}"
        return self.note or "the two meshes cannot be compared"

    def view(self, side: str) -> PairView:
        """What ``side`` shows: see :class:`PairView`."""
        drawn = self.drawn_mesh(side)
        head = f"{side.upper()}: {self.name(side)}, {drawn.n_vertices} vertices"
        name = DISTANCE_KINDS[self.kind]
        if self._pick is None:
            return PairView(None, "plain", None, None, None, f"{head}\nclick A or B to pick")
        from_side, v = self._pick
        matches = self._drawn_matches()
        if matches is None:
            marker = v if from_side == side else None
            return PairView(None, "plain", None, marker, None, f"{head}\n{name}: {self._missing()}")
        _, w, dist, back = matches
        note = "".join(f"\n{n}" for n in (self.note, self.arrival_note()) if n)
        # markers are drawn-mesh vertices, labels the input's numbers
        fv, fw = self.picked[1], self.best_match()[1]
        if from_side == side:
            mutual = f"not mutual: back to vertex {self.back_match()} (yellow)"
            mutual = "mutual" if back == v else mutual
            legend = f"{head}\npicked vertex {fv}\nbest match on {other(side).upper()}: vertex {fw}"
            back_marker = None if back == v else back
            return PairView(None, "plain", None, v, back_marker, f"{legend}\n{mutual}{note}")
        d = self._drawn_distance(side)
        source = f"from vertex {fv} of {from_side.upper()}"
        if self.distance_display == "threshold":
            thr, share = self.threshold(side)
            below = f"{name.lower()} < {thr:.3g}"
            legend = f"{head}\nblue: {below}, {100 * share:.1f} % of {side.upper()}\n{source}"
            legend += f"; best match vertex {fw}{note}"
            labels = [f"{below} ({100 * share:.1f} %)", "the rest"]
            return PairView(d, "threshold", thr, w, None, legend, f"{name} < {thr:.3g}", labels)
        span = f"white {float(np.nanmin(d)):.3g} to red {float(np.nanmax(d)):.3g}"  # the bar's
        legend = f"{head}\n{name} {source}: {span}\n"
        legend += f"best match: vertex {fw} (d = {dist:.3g}){note}"
        return PairView(d, "sequential", None, w, None, legend, name, scale=self._spread(side, d))


def _drawn_vertices(mesh: Mesh, vertices, name: str) -> np.ndarray:
    """The drawn mesh's vertices of input ``vertices`` (ValueError for one no face uses)."""
    checked = check_vertices(vertices, mesh.n_file_vertices, f"vertices of {name}")
    try:
        return np.array([mesh.mesh_vertex(v) for v in checked], dtype=np.int64)
    except MeshError as exc:
        raise ValueError(f"{name}: {exc}") from None
