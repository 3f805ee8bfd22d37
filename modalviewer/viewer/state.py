"""The viewer's state: what is loaded, computed, displayed and picked (no Qt, no VTK).

:class:`ViewerState` is the single source of truth the scene, panels and plots redraw
from.  Fields that only need validating are evented (``style``, ``animation`` and
``compute_settings``: ``state.animation.speed = 50``; ``camera``, ``up_axis``); changes
that do more go through methods (``set_display``, ``set_pick``, ...), which change only
what they are given, except for the threshold rule (:meth:`ViewerState._match_threshold`).
Values computed from it: :attr:`ViewerState.derived`; its words: :mod:`.wording`.

Events (``state.events.<name>.connect(callback)``), emitted on the thread that changed
the state: ``mesh()`` (new mesh or none; spectra, pick and display reset),
``spectra(operator)``, ``display()``, ``style()``, ``pick()``, ``compute_settings()``,
``scale_range()``, ``animation()``, ``camera(new, old)`` (a preset, a restored session),
``signature_curve()`` (the exact curve arrived) and ``up_axis(new, old)``.
"""

from __future__ import annotations

import operator as op_
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import ClassVar

import numpy as np
from psygnal import Signal, SignalGroup, SignalGroupDescriptor, evented

from ..core.mesh import Mesh
from ..core.operators import (
    DEFAULT_K,
    DISTANCE_KINDS,
    OPERATOR_INFO,
    default_k,
    operator_for_distance,
    operator_info,
    signature_kind,
)
from ..core.spectrum import Spectrum, on_solver_mesh
from ..spectra import cached_or_computed
from .camera import AXES
from .derived import DerivedValues

DISPLAY_KINDS = ("none", "mode", "distance", "signature", "curvature", "field")
DISTANCE_DISPLAYS = ("continuous", "threshold")
DEFAULT_THRESHOLD_SHARE = 0.1
"""Share of the surface a first threshold map marks similar (the paper's maps mark a few
per cent to a tenth)."""
DEFAULT_THRESHOLD_FRACTION = 0.2
"""A threshold as a fraction of the largest distance, where none was set and no share
applies (a map drawn without ``keep_share``)."""
NEXT_MAP = "next map"
""":attr:`ViewerState.threshold_map` when the next threshold map keeps a fraction set."""
SHELL_COLORINGS = ("deformed", "normal", "magnitude")
"""How a 3D vibration mode is shown: "deformed" (the surface displaced by the mode at the
amplitude, coloured by the displacement magnitude), "normal" (its normal component
against smoothed normals on the rest shape) or "magnitude" (its magnitude on the rest
shape).  Sessions and settings holding the former "auto" get "deformed"."""
COLOR_RANGES = ("auto", "symmetric", "robust", "spread", "limits")
"""Colour ranges: "symmetric" about the largest |value| (sequential fields: 0 to the
largest value), "robust" (the 99th area-weighted percentile of |value|, beyond it
clipped), "spread" (one-signed fields: colours by the share of the area below each value,
the colour bar labelled with the values; see :mod:`.color_scale`), "limits"
(:attr:`Style.color_limits`), "auto" (for distances, signatures and curvature, where
one extreme dominates: spread where a tenth of the robust range would cover more than a
quarter of the surface, else robust; symmetric for modes)."""
RENDER_STYLES = ("paper", "shaded")


@evented
@dataclass
class ComputeSettings:
    """What the next computation computes (the Compute panel); fields validated, evented."""

    operator: str = "modified_dirichlet"
    k: int = DEFAULT_K
    bending: float = 1.0
    membrane: float = 1.0
    rescale: bool = False
    coarse: bool = False

    def __setattr__(self, name: str, value) -> None:
        if name == "operator":
            operator_info(value)  # a ValueError naming the operators for an unknown one
        elif name == "k":
            value = int(value)
            if value < 1:
                raise ValueError("the number of modes must be at least 1")
        super().__setattr__(name, value)

    def key(self, operator: str | None = None, k: int | None = None) -> SpectrumKey:
        """The key of ``operator``'s spectrum of ``k`` modes (defaults: these settings')."""
        op = operator or self.operator
        weights = (self.bending, self.membrane) if operator_info(op).has_weights else (1, 1)
        k = int(k if k is not None else self.k)
        return SpectrumKey(op, k, *map(float, weights), bool(self.rescale), bool(self.coarse))


@dataclass(frozen=True)
class SpectrumKey:
    """Identifies one computed spectrum of the loaded mesh."""

    operator: str
    k: int
    bending: float = 1.0
    membrane: float = 1.0
    rescale: bool = False
    coarse: bool = False

    def describe(self) -> str:
        info = operator_info(self.operator)
        extra = []
        if info.has_weights and (self.bending, self.membrane) != (1.0, 1.0):
            extra.append(f"bending {self.bending:g}, membrane {self.membrane:g}")
        if self.rescale:
            extra.append("unit area")
        if self.coarse:
            extra.append("coarse-to-fine")
        tail = f" ({'; '.join(extra)})" if extra else ""
        return f"{info.label}, {self.k} modes{tail}"

    def spectrum(self, mesh: Mesh, cache, progress, cancel, on_modes=None) -> Spectrum:
        """:func:`~modalviewer.spectra.cached_or_computed` of ``mesh`` (of unit area
        already where ``rescale``), large exact solves in a child process."""
        return cached_or_computed(
            mesh, self.operator, self.k, self.bending, self.membrane, cache=cache,
            progress=progress, cancel=cancel, on_modes=on_modes, coarse=self.coarse,
            child_process=True,
        )  # fmt: skip

    def cached(self, mesh: Mesh, cache) -> bool:
        """Whether the exact spectrum of ``mesh`` for this key is in ``cache``."""
        return cache.path(mesh, self.operator, self.k, self.bending, self.membrane).is_file()


def unit_area(mesh: Mesh) -> Mesh:
    """``mesh`` scaled to unit area (the viewer's and the shape pair's arithmetic, so
    their spectra share disk cache entries)."""
    factor = 1.0 / np.sqrt(mesh.total_area)
    return Mesh(mesh.vertices * factor, mesh.faces, report=mesh.report, file_map=mesh.file_map)


@dataclass(frozen=True)
class Display:
    """What the surface shows."""

    kind: str = "none"  # one of DISPLAY_KINDS
    operator: str | None = None  # a mode's spectrum
    mode: int = 0
    distance_kind: str = "vibration"  # also the signature's spectrum and kind
    distance_display: str = "continuous"  # or "threshold"
    threshold: float = DEFAULT_THRESHOLD_FRACTION  # of the largest distance, (0..1]
    threshold_share: float = DEFAULT_THRESHOLD_SHARE  # of the area the threshold marks
    keep_share: bool = True  # a new threshold map keeps the share, not the fraction
    signature_sample: int = 50  # the signature's scale sample, 0..99
    signature_time: float | None = None  # a typed scale t, else the sample's
    field: str | None = None  # the field shown with kind "field"

    def blank(self) -> Display:
        """This display as a newly loaded mesh shows it: nothing, other choices kept."""
        return replace(self, kind="none", operator=None, mode=0, field=None)


class ViewerEvents(SignalGroup):
    """The state's events besides its fields' (``camera``, ``up_axis``)."""

    mesh = Signal()
    spectra = Signal(str)
    display = Signal()
    style = Signal()
    pick = Signal()
    compute_settings = Signal()
    scale_range = Signal()
    animation = Signal()
    signature_curve = Signal()


@evented
@dataclass
class Style:
    """How the picture is drawn; fields validated, evented.  The colour range and its
    limits are set together by :meth:`ViewerState.set_color_range`."""

    isolines: int = 12  # clipped to 0..60
    shell_coloring: str = "deformed"  # 3D modes: one of SHELL_COLORINGS ("auto": deformed)
    ghost: bool = True  # the rest shape, faint, behind a deformed 3D mode
    color_range: str = "auto"  # one of COLOR_RANGES
    color_limits: tuple[float, float] | None = None  # (low, high) of the "limits" range
    render: str = "paper"  # paper: white zero, saturated colours; shaded: light kit
    colorbar: bool = True  # legend and colour bar, on screen and in exports
    log_signature: bool = False  # signatures coloured by log10(S / smallest S)

    def __setattr__(self, name: str, value) -> None:
        if name == "isolines":
            value = int(np.clip(value, 0, 60))
        elif name == "shell_coloring":
            value = "deformed" if value == "auto" else value
            if value not in SHELL_COLORINGS:
                raise ValueError(f"colouring must be one of {SHELL_COLORINGS}")
        elif name == "render" and value not in RENDER_STYLES:
            raise ValueError(f"render style must be one of {RENDER_STYLES}")
        elif name in ("ghost", "colorbar", "log_signature"):
            value = bool(value)
        super().__setattr__(name, value)


@evented
@dataclass
class Animation:
    """The vibration's animation; fields clipped, evented.  Only a mode plays."""

    playing: bool = False
    # largest displacement of a mode, in percent of a quarter of the bounding-box diagonal
    # (40: a tenth of the diagonal), of the deformed shape and of the animation's peak
    amplitude: int = 40  # 0..100
    speed: int = 30  # tenths of a radian per second, 1..100

    def __setattr__(self, name: str, value) -> None:
        if name == "playing":
            value = bool(value)
        elif name in ("amplitude", "speed"):
            value = int(np.clip(value, 0 if name == "amplitude" else 1, 100))
        super().__setattr__(name, value)


@dataclass(eq=False)
class ViewerState:
    """The viewer's state (events: the module docstring).  ``camera``: set by a preset or
    a session, the scene applies it (an equal one again too; "fit": fitted to the
    shape).  ``up_axis``: "+x" ... "-z", or None ("auto": detected where confident, else
    +Y; :meth:`.derived.DerivedValues.up_axis`)."""

    events: ClassVar = SignalGroupDescriptor(
        signal_group_class=ViewerEvents,
        equality_operators={"camera": op_.is_},
        # attributes named as events are not evented fields: their events are emitted
        signal_aliases=dict.fromkeys(
            ("mesh", "spectra", "display", "style", "compute_settings", "animation")
        ),
    )
    camera: dict | None = None
    up_axis: str | None = None

    def __setattr__(self, name: str, value) -> None:
        if name == "up_axis":
            value = None if value in (None, "auto") else str(value).lower()
            if value is not None and value not in AXES:
                raise ValueError(f"up axis must be auto or one of {', '.join(AXES)}")
        super().__setattr__(name, value)

    def __post_init__(self) -> None:
        self.mesh: Mesh | None = None
        self.mesh_path: Path | None = None
        self.mesh_repairs: list[str] = []  # repairs applied after loading, in order
        self.compute_settings = ComputeSettings()
        self.spectra: dict[SpectrumKey, Spectrum] = {}
        self.fields: dict[str, np.ndarray] = {}  # per-vertex values a script gave
        self._latest: dict[str, SpectrumKey] = {}
        self.computing: set[SpectrumKey] = set()  # spectra being computed or queued
        self.display = Display()
        self.picked: int | None = None
        self.t_range: tuple[float, float] | None = None
        self.style = Style()
        self.style.events.all.connect(lambda: self.events.style.emit())
        self.animation = Animation()
        self.animation.events.all.connect(self._animation_changed)
        self.compute_settings.events.all.connect(lambda: self.events.compute_settings.emit())
        # the map (DerivedValues.map_identity) threshold and share were last matched on;
        # None before the first, NEXT_MAP when the next one keeps a fraction set
        self.threshold_map: tuple | str | None = None

    def _animation_changed(self) -> None:
        if self.animation.playing and self.display.kind != "mode":
            with self.animation.events.blocked():
                self.animation.playing = False  # only a mode plays
        else:
            self.events.animation.emit()

    @cached_property
    def derived(self) -> DerivedValues:
        """The values computed from this state, created on first use."""
        return DerivedValues(self)

    # ------------------------------------------------------------- mesh
    def set_mesh(
        self, mesh: Mesh | None, path: Path | str | None = None, repairs: list[str] | None = None
    ) -> None:
        """Load ``mesh`` (read from ``path``, then given ``repairs``), dropping the previous
        mesh's spectra, pick and display; the state holds ``mesh.solver_mesh``."""
        self.mesh = mesh.solver_mesh if mesh is not None else None
        self.mesh_repairs = list(repairs or [])
        self.mesh_path = Path(path) if path is not None else None
        self.spectra.clear()
        self.fields.clear()
        self._latest.clear()
        self.computing.clear()
        self.picked = None
        self.display = self.display.blank()
        with self.events.blocked():  # the mesh event tells them all
            if mesh is not None:
                self.compute_settings.k = default_k(mesh.n_vertices)
            self.animation.playing = False
            self.camera = self.up_axis = None
        self.events.mesh.emit()

    def compute_mesh(self, key: SpectrumKey | None = None) -> Mesh:
        """The mesh a spectrum is computed on: the loaded one, or a copy of unit area."""
        if self.mesh is None:
            raise ValueError("no mesh is loaded")
        rescale = key.rescale if key is not None else self.compute_settings.rescale
        return unit_area(self.mesh) if rescale else self.mesh

    # ---------------------------------------------------------- spectra
    def add_spectrum(self, key: SpectrumKey, spec: Spectrum, table=None) -> None:
        """Store a spectrum (and its signature table) as its operator's, dropping the
        operator's other keys (exact ones come back from the cache).  First modes of a
        running computation never replace a complete spectrum of ``key`` nor one on
        screen with more modes, and reset nothing the user chose."""
        if self.mesh is not None:
            spec = on_solver_mesh(spec, self.mesh)  # one of the input's numbering
        if self.mesh is None or spec.n_vertices != self.mesh.n_vertices:
            raise ValueError("the spectrum does not belong to the loaded mesh")
        if not spec.is_complete:
            if self.has_spectrum(key):
                return  # the whole spectrum is in already
            shown_key = self._latest.get(key.operator)
            shown = self.spectra.get(shown_key) if shown_key not in (None, key) else None
            if shown is not None and spec.k < shown.k:
                return  # the operator's spectrum on screen stays until as many are in
        for other in [k for k in self.spectra if k.operator == key.operator and k != key]:
            del self.spectra[other]
        self.spectra[key] = spec
        self._latest[key.operator] = key
        if self.display.kind == "mode" and self.display.operator == key.operator:
            self.display = replace(self.display, mode=min(self.display.mode, spec.k - 1))
        if table is not None:
            self.derived.keep_table(spec, table)
        self._match_threshold()
        self.events.spectra.emit(key.operator)
        if self.display_operator() == key.operator:  # None unless a mode, map or signature
            self.events.display.emit()

    def set_computing(self, key: SpectrumKey, computing: bool) -> None:
        """Mark the spectrum of ``key`` as computed or queued (or not)."""
        if computing == (key in self.computing):
            return
        (self.computing.add if computing else self.computing.discard)(key)
        self.events.spectra.emit(key.operator)
        if self.display_operator() == key.operator:
            self.events.display.emit()

    def spectrum(self, operator: str | None) -> Spectrum | None:
        """The most recent spectrum of ``operator``, or None."""
        return self.spectra.get(self._latest.get(operator))

    def spectrum_key(self, operator: str) -> SpectrumKey | None:
        return self._latest.get(operator)

    def operators_computed(self) -> list[str]:
        return [op for op in OPERATOR_INFO if op in self._latest]

    def has_spectrum(self, key: SpectrumKey) -> bool:
        """Whether the whole spectrum of ``key`` is in (first modes do not count)."""
        spec = self.spectra.get(key)
        return spec is not None and spec.is_complete

    def modes_ready(self, operator: str | None) -> tuple[int, int]:
        """(modes in, modes asked for) of ``operator``'s spectrum; (0, 0) with none."""
        spec = self.spectrum(operator)
        return (0, 0) if spec is None else (spec.k, spec.modes_requested)

    # --------------------------------------------------------- settings
    def set_color_range(self, mode: str, limits: tuple[float, float] | None = None) -> None:
        """The colour range (:data:`COLOR_RANGES`) and, if given, its ``limits`` (low <
        high; "limits" needs them, now or before)."""
        if mode not in COLOR_RANGES:
            raise ValueError(f"colour range must be one of {COLOR_RANGES}")
        if limits is not None:
            lo, hi = (float(x) for x in limits)
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise ValueError("colour limits need low < high")
            limits = (lo, hi)
        else:
            limits = self.style.color_limits
        if mode == "limits" and limits is None:
            raise ValueError("the 'limits' colour range needs limits (low, high)")
        if (mode, limits) != (self.style.color_range, self.style.color_limits):
            with self.style.events.all.blocked():  # one redraw for both
                self.style.color_range, self.style.color_limits = mode, limits
            self.events.style.emit()

    def set_scale_range(self, t_range: tuple[float, float] | None) -> None:
        """The scale range (t1, t2) of signatures and distances; None for the default."""
        if t_range is not None:
            t1, t2 = (float(t) for t in t_range)
            if not 0 < t1 < t2:
                raise ValueError("the scale range needs 0 < t1 < t2")
            t_range = (t1, t2)
        if t_range != self.t_range:
            self.t_range = t_range
            self._match_threshold()
            self.events.scale_range.emit()
            if self.display.kind in ("distance", "signature"):
                self.events.display.emit()

    # ---------------------------------------------------------- display
    def set_display(self, **changes) -> None:
        """Change what is shown; fields of :class:`Display`.  Validated before storing."""
        if "signature_sample" in changes and "signature_time" not in changes:
            changes["signature_time"] = None  # a sample chosen replaces a typed scale
        new = replace(self.display, **changes)
        if new.kind not in DISPLAY_KINDS:
            raise ValueError(f"display kind must be one of {DISPLAY_KINDS}")
        if new.distance_kind not in DISTANCE_KINDS:
            raise ValueError(f"distance kind must be one of {tuple(DISTANCE_KINDS)}")
        if new.distance_display not in DISTANCE_DISPLAYS:
            raise ValueError(f"distance display must be one of {DISTANCE_DISPLAYS}")
        if new.kind == "field" and new.field not in self.fields:
            raise ValueError(f"no field {new.field!r}; add it with add_field(name, values)")
        if new.kind == "mode":
            spec = self.spectrum(new.operator)
            if spec is None:
                raise ValueError(f"no spectrum of {new.operator!r} has been computed")
            new = replace(new, mode=int(np.clip(new.mode, 0, spec.k - 1)))
        t = None if new.signature_time is None else float(new.signature_time)
        if t is not None and not (np.isfinite(t) and t > 0):
            raise ValueError("the signature scale t must be positive and finite")
        new = replace(
            new,
            threshold=float(np.clip(new.threshold, 1e-4, 1.0)),
            threshold_share=float(np.clip(new.threshold_share, 0.0, 1.0)),
            signature_sample=int(np.clip(new.signature_sample, 0, 99)),
            signature_time=t,
        )
        if new == self.display:
            return
        wave_changed = signature_kind(new.distance_kind) != signature_kind(
            self.display.distance_kind
        )
        self.display = new
        if wave_changed and self.t_range is not None:
            # a scale range is of times t, a wave kernel's of energies E: neither carries over
            self.t_range = None
            self.events.scale_range.emit()
        self._match_threshold(
            fraction_set="threshold" in changes,
            share_set="threshold_share" in changes,
        )
        if new.kind != "mode":
            self.animation.playing = False
        self.events.display.emit()

    def add_field(self, name: str, values) -> None:
        """Keep finite per-vertex ``values`` as the field ``name`` (replacing one of that
        name) for ``set_display(kind="field", field=name)``; a new mesh drops them."""
        if self.mesh is None:
            raise ValueError("no mesh is loaded")
        name = str(name)
        if not name:
            raise ValueError("a field needs a name")
        values = np.array(values, dtype=np.float64)
        if self.mesh.renumbered and values.shape == (self.mesh.n_file_vertices,):
            values = values[self.mesh.file_vertices]  # the input's numbering
        if values.shape != (self.mesh.n_vertices,):
            raise ValueError(
                f"field {name!r} has shape {values.shape}; the mesh has "
                f"{self.mesh.n_file_vertices} vertices: give one value per vertex"
            )
        if not np.all(np.isfinite(values)):
            raise ValueError(f"field {name!r} has values that are not finite")
        self.fields[name] = values
        if self.display.kind == "field" and self.display.field == name:
            self.events.display.emit()

    def show_mode(self, index: int, operator: str | None = None) -> None:
        op = operator or self.display.operator or next(iter(self.operators_computed()), None)
        self.set_display(kind="mode", operator=op, mode=index)

    def first_nonzero_mode(self, operator: str) -> int:
        spec = self.spectrum(operator)
        if spec is None:
            return 0
        nonzero = ~spec.zero_mode_mask()
        return int(np.argmax(nonzero)) if nonzero.any() else 0

    def current_operator(self) -> str | None:
        """The operator of the mode (last) shown, else the display's, else the first computed."""
        for op in (self.display.operator, self.display_operator()):
            if op is not None and self.spectrum(op) is not None:
                return op
        return next(iter(self.operators_computed()), None)

    @property
    def picked_file_vertex(self) -> int | None:
        """The picked vertex's number in the file; :attr:`picked` is the solver mesh's."""
        if self.picked is None or self.mesh is None:
            return None
        return self.mesh.file_vertex(self.picked)

    def set_pick_file_vertex(self, file_index: int | None) -> None:
        """Pick vertex ``file_index`` of the file (a ValueError for one no face uses)."""
        if file_index is not None and self.mesh is not None:  # else set_pick says no mesh
            file_index = self.mesh.mesh_vertex(file_index)
        self.set_pick(file_index)

    def set_pick(self, vertex: int | None) -> None:
        """Pick vertex ``vertex`` of the solver mesh (as a click finds it)."""
        if vertex is not None:
            if self.mesh is None:
                raise ValueError("no mesh is loaded")
            vertex = int(vertex)
            if not 0 <= vertex < self.mesh.n_vertices:
                raise ValueError(f"Vertex {vertex} does not exist (0..{self.mesh.n_vertices - 1}).")
        if vertex != self.picked:
            self.picked = vertex
            self._match_threshold()
            self.events.pick.emit()
            if self.display.kind == "distance":
                self.events.display.emit()

    def display_operator(self) -> str | None:
        """The operator whose spectrum the current display is made of."""
        d = self.display
        if d.kind == "mode":
            return d.operator
        if d.kind in ("distance", "signature"):
            return operator_for_distance(d.distance_kind)
        return None

    def is_coarse(self, operator: str | None) -> bool:
        """Whether ``operator``'s spectrum was computed coarse-to-fine (approximate)."""
        key = self._latest.get(operator)
        return key is not None and key.coarse and key in self.spectra

    def _match_threshold(self, fraction_set: bool = False, share_set: bool = False) -> None:
        """The threshold rule: match ``display.threshold`` (a fraction of the largest
        distance) and ``threshold_share`` (of the area) on the threshold map on screen.
        Distances are so skewed that one fraction marks most of the surface from one
        vertex and little from another, so with ``keep_share`` a new map gets the
        fraction marking the share; a fraction set (``fraction_set``), or any without
        ``keep_share``, sets the share; a share set sets the fraction.  Emits nothing."""
        d = self.display
        on_screen = d.kind == "distance" and d.distance_display == "threshold"
        dist = self.derived.distance_map() if on_screen else None  # none for other pictures
        if dist is None:
            # a fraction or share set for a map still to come is kept for it (and the
            # display stays as given: a request's "display unchanged" test must not see
            # a change here)
            if fraction_set:
                self.threshold_map = NEXT_MAP
            elif share_set:
                self.threshold_map = None
            return
        identity = self.derived.map_identity()
        if fraction_set or self.threshold_map == NEXT_MAP or not d.keep_share:
            share = self.derived.surface_share(dist, d.threshold * float(dist.max()))
            self.display = replace(d, threshold_share=share)
        elif share_set or identity != self.threshold_map:
            fraction = self.derived.threshold_for_share(d.threshold_share, dist)
            self.display = replace(d, threshold=fraction)
        self.threshold_map = identity
