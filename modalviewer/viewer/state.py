"""The viewer's state: what is loaded, computed, displayed and picked (no Qt, no VTK).

:class:`ViewerState` is the single source of truth of the viewer.  The 3D scene, every
panel, the status bar and the plots observe its events and redraw from it; they keep
no state of their own.  Input (a click, a slider, a script, the CLI) goes through its
setters, which validate, store and emit.  Everything shown can be derived from it:
:meth:`ViewerState.field` is the per-vertex picture, :meth:`ViewerState.legend` its
legend and :meth:`ViewerState.summary` the status line.

Events (``state.events.<name>.connect(callback)``), all emitted on the thread that
changed the state (the GUI thread in the viewer):

- ``mesh()``: a new mesh (or none) is loaded; spectra, pick and display were reset.
- ``spectra(operator)``: a spectrum of ``operator`` was added or replaced.
- ``display()``: what is drawn changed (:class:`Display`), including the threshold.
- ``style()``: isolines, colouring of 3D modes, colour bar, render style.
- ``pick()``: the picked vertex changed (:attr:`ViewerState.picked` is the mesh's index;
  what is shown and saved is :attr:`ViewerState.picked_file_vertex`, the file's number).
- ``compute_settings()``: operator, k, weights or options of the next computation.
- ``scale_range()``: the distance scale range (t1, t2) changed.
- ``animation()``: playing, amplitude or speed changed.
- ``camera()``: a camera was set through the state (a preset, a restored session).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from psygnal import Signal, SignalGroup

from ..core.curvature import total_curvature
from ..core.laplacian import lumped_masses, vertex_normals
from ..core.mesh import Mesh, _plural
from ..core.operators import (
    DISTANCE_KINDS,
    OPERATOR_INFO,
    operator_for_distance,
    operator_info,
)
from ..core.signatures import SignatureTable, signature
from ..core.spectrum import Spectrum
from .mode_scalar import default_vector_coloring, smoothed_normals, vector_mode_scalar

DISPLAY_KINDS = ("none", "mode", "distance", "signature", "curvature")
DISTANCE_DISPLAYS = ("continuous", "threshold")
DEFAULT_THRESHOLD_SHARE = 0.1
"""Share of the surface a first threshold map marks similar (the paper's maps mark a few
per cent to a tenth)."""
SHELL_COLORINGS = ("auto", "normal", "magnitude")
RENDER_STYLES = ("paper", "shaded")


def percent_text(fraction: float) -> str:
    """A relative error as a short percentage: "< 0.01 %", "0.24 %", "2.2 %", "21 %",
    "135 %" (with a no-break space, so a wrapped legend keeps number and sign together);
    below 0.01 % the digits would only show how converged a mode is, not its error."""
    value = 100.0 * float(fraction)
    if 0 < value < 0.01:
        return "<\u00a00.01\u00a0%"
    return f"{value:.0f}\u00a0%" if value >= 10 else f"{value:.2g}\u00a0%"


def default_k(n_vertices: int) -> int:
    """A mode count suited to the mesh: 100 for most meshes, fewer for tiny ones."""
    return int(max(2, min(100, n_vertices // 4)))


@dataclass(frozen=True)
class ComputeSettings:
    """What the next computation computes (the Compute panel's fields)."""

    operator: str = "modified_dirichlet"
    k: int = 100
    bending: float = 1.0
    membrane: float = 1.0
    rescale: bool = False
    coarse: bool = False
    preview: bool = True  # big meshes: a preview spectrum first, the exact one after

    def key(self, operator: str | None = None, k: int | None = None) -> SpectrumKey:
        op = operator or self.operator
        weights = operator_info(op).has_weights
        return SpectrumKey(
            operator=op,
            k=int(k if k is not None else self.k),
            bending=float(self.bending) if weights else 1.0,
            membrane=float(self.membrane) if weights else 1.0,
            rescale=bool(self.rescale),
            coarse=bool(self.coarse),
        )


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


@dataclass(frozen=True)
class Display:
    """What the surface shows.

    kind : "none" | "mode" | "distance" | "signature" | "curvature".
    operator : the spectrum a mode belongs to.
    mode : index of the mode shown.
    distance_kind : "vibration" | "feature" | "hks" (also picks the signature's spectrum).
    distance_display : "continuous" | "threshold".
    threshold : threshold as a fraction of the largest distance (0..1].
    threshold_by_share : the threshold map keeps the share of the surface it marks when
        its distances change (another pick, a new spectrum), instead of the fraction.
    signature_sample : index of the scale a signature is shown at (0..99).
    """

    kind: str = "none"
    operator: str | None = None
    mode: int = 0
    distance_kind: str = "vibration"
    distance_display: str = "continuous"
    threshold: float = 0.2
    threshold_by_share: bool = True
    signature_sample: int = 50

    def blank(self) -> Display:
        """This display as a newly loaded mesh shows it: nothing, other choices kept."""
        return replace(self, kind="none", operator=None, mode=0)


@dataclass
class Field:
    """A per-vertex picture derived from the state, ready for the scene to draw.

    colormap : "diverging" (blue / white / orange), "sequential" (white to red),
    "threshold" (blue = similar) or "plain" (no field: the grey surface).
    threshold : for "threshold": values (the distances) up to it are blue.
    """

    values: np.ndarray
    colormap: str
    isolines: int = 0
    displacement: np.ndarray | None = None
    clim: tuple[float, float] | None = None
    title: str = ""
    legend: str = ""
    share_similar: float | None = None
    threshold: float | None = None


def _take_signs(spec: Spectrum, preview: Spectrum) -> None:
    """Flip modes of ``spec`` in place so each has a non-negative Mass inner product
    with the same mode of ``preview``: a mode's sign is arbitrary, and an exact spectrum
    replacing its preview should not swap the colours of the mode on screen."""
    k = min(spec.k, preview.k)
    if spec.modes.shape[:-1] != preview.modes.shape[:-1] or k == 0:
        return
    if not spec.modes.flags.writeable:
        return
    a = spec.modes[..., :k].reshape(spec.modes.shape[0], -1, k)
    b = preview.modes[..., :k].reshape(preview.modes.shape[0], -1, k)
    inner = np.einsum("v,vcj,vcj->j", spec.mass, a, b)
    flip = np.flatnonzero(inner < 0)
    if flip.size:
        spec.modes[..., flip] *= -1.0


class ViewerEvents(SignalGroup):
    mesh = Signal()
    spectra = Signal(str)
    display = Signal()
    style = Signal()
    pick = Signal()
    compute_settings = Signal()
    scale_range = Signal()
    animation = Signal()
    camera = Signal()


@dataclass
class _Style:
    isolines: int = 12
    shell_coloring: str = "auto"  # auto: magnitude on meshes with sharp features
    render: str = "paper"  # paper: white zero, saturated colours; shaded: light kit
    colorbar: bool = True  # legend and colour bar, on screen and in exports


@dataclass
class Animation:
    playing: bool = False
    amplitude: int = 8  # percent of a quarter of the bounding-box diagonal
    speed: int = 30  # tenths of a radian per second


@dataclass
class _Derived:
    """Values computed from the state and kept until it changes (not part of it)."""

    normals: np.ndarray | None = None
    smooth_normals: np.ndarray | None = None
    auto_coloring: str | None = None
    tables: dict = field(default_factory=dict)
    distance: dict = field(default_factory=dict)
    curvature: np.ndarray | None = None
    vertex_areas: np.ndarray | None = None


class ViewerState:
    """The viewer's state; see the module docstring for its events."""

    def __init__(self) -> None:
        self.events = ViewerEvents()
        self.mesh: Mesh | None = None
        self.mesh_path: Path | None = None
        self.mesh_repairs: list[str] = []  # repairs applied after loading, in order
        self.compute_settings = ComputeSettings()
        self.spectra: dict[SpectrumKey, Spectrum] = {}
        self._latest: dict[str, SpectrumKey] = {}
        self.computing: set[SpectrumKey] = set()  # spectra being computed or queued
        self.display = Display()
        self.picked: int | None = None
        self.t_range: tuple[float, float] | None = None
        self.style = _Style()
        self.animation = Animation()
        self.camera: dict | None = None
        self._derived = _Derived()
        # the share of the surface threshold maps mark, and the map it was last set for
        self._share_target = DEFAULT_THRESHOLD_SHARE
        self._share_map: tuple | None = None
        self._fraction_set = False  # a threshold was set while no map was on screen

    # ------------------------------------------------------------- mesh
    def set_mesh(
        self, mesh: Mesh | None, path: Path | str | None = None, repairs: list[str] | None = None
    ) -> None:
        """Load ``mesh`` (read from ``path``, then given ``repairs``): spectra, pick and
        display of the previous mesh are dropped."""
        self.mesh = mesh
        self.mesh_repairs = list(repairs or [])
        self.mesh_path = Path(path) if path is not None else None
        self.spectra.clear()
        self._latest.clear()
        self.computing.clear()
        self._derived = _Derived()
        if mesh is not None:
            self._derived.normals = vertex_normals(mesh)
            self.compute_settings = replace(self.compute_settings, k=default_k(mesh.n_vertices))
        self.picked = None
        self.animation.playing = False
        self.display = self.display.blank()
        self.camera = None
        self.events.mesh.emit()

    @property
    def normals(self) -> np.ndarray | None:
        return self._derived.normals

    def compute_mesh(self, key: SpectrumKey | None = None) -> Mesh:
        """The mesh a spectrum is computed on: the loaded one, or a copy of unit area."""
        if self.mesh is None:
            raise ValueError("no mesh is loaded")
        rescale = key.rescale if key is not None else self.compute_settings.rescale
        if not rescale:
            return self.mesh
        factor = 1.0 / np.sqrt(self.mesh.total_area)
        return Mesh(
            self.mesh.vertices * factor,
            self.mesh.faces,
            report=self.mesh.report,
            file_map=self.mesh.file_map,
        )

    # ---------------------------------------------------------- spectra
    def add_spectrum(self, key: SpectrumKey, spec: Spectrum, table=None) -> None:
        """Store a computed spectrum (and its signature table, if already built).

        It becomes the spectrum shown for its operator; the operator's spectra of other
        keys (another k, other weights) are dropped: nothing shows them any more, and at
        130k vertices each holds 100 to 300 MB (exact ones come back from the cache)."""
        if self.mesh is None or spec.n_vertices != self.mesh.n_vertices:
            raise ValueError("the spectrum does not belong to the loaded mesh")
        if spec.is_preview and self.has_spectrum(key):
            return  # the exact spectrum is in already
        shown = self.spectra.get(key)
        if shown is not None and shown.is_preview and not spec.is_preview:
            _take_signs(spec, shown)
        for other in [k for k in self.spectra if k.operator == key.operator and k != key]:
            del self.spectra[other]
        self.spectra[key] = spec
        self._latest[key.operator] = key
        if self.display.kind == "mode" and self.display.operator == key.operator:
            self.display = replace(self.display, mode=min(self.display.mode, spec.k - 1))
        stale = [k for k in self._derived.tables if k[0] == key.operator]
        for k in stale:
            del self._derived.tables[k]
        self._derived.distance.clear()
        if table is not None:
            self._derived.tables[(key.operator, id(spec), table.t_range)] = table
        self._sync_threshold()
        self.events.spectra.emit(key.operator)
        if self.display.kind in ("mode", "distance", "signature"):
            if self.display_operator() == key.operator:
                self.events.display.emit()

    def set_computing(self, key: SpectrumKey, computing: bool) -> None:
        """Whether the spectrum of ``key`` is being computed or waits its turn: the status
        line says so while no spectrum is on screen, and behind a preview the panels and
        the picture's legend say the exact spectrum follows (:meth:`exact_follows`)."""
        if computing == (key in self.computing):
            return
        if computing:
            self.computing.add(key)
        else:
            self.computing.discard(key)
        self.events.spectra.emit(key.operator)
        if self.display_operator() == key.operator:
            self.events.display.emit()

    def exact_follows(self, operator: str | None) -> bool:
        """True if the spectrum shown for ``operator`` is a preview whose exact spectrum
        is on its way."""
        key = self._latest.get(operator) if operator else None
        if key is None or key not in self.computing:
            return False
        spec = self.spectra.get(key)
        return spec is not None and spec.is_preview

    def spectrum(self, operator: str | None) -> Spectrum | None:
        """The most recent spectrum of ``operator``, or None."""
        key = self._latest.get(operator) if operator else None
        return self.spectra.get(key) if key is not None else None

    def spectrum_key(self, operator: str) -> SpectrumKey | None:
        return self._latest.get(operator)

    def operators_computed(self) -> list[str]:
        return [op for op in OPERATOR_INFO if op in self._latest]

    def has_spectrum(self, key: SpectrumKey) -> bool:
        """Whether the exact spectrum of ``key`` is in (a preview does not count)."""
        spec = self.spectra.get(key)
        return spec is not None and not spec.is_preview

    # --------------------------------------------------------- settings
    def set_compute_settings(self, **changes) -> None:
        """Change fields of :class:`ComputeSettings` (operator, k, bending, ...)."""
        if "operator" in changes:
            operator_info(changes["operator"])
        if "k" in changes:
            changes["k"] = int(changes["k"])
            if changes["k"] < 1:
                raise ValueError("the number of modes must be at least 1")
        new = replace(self.compute_settings, **changes)
        if new != self.compute_settings:
            self.compute_settings = new
            self.events.compute_settings.emit()

    def set_isolines(self, count: int) -> None:
        count = int(np.clip(count, 0, 60))
        if count != self.style.isolines:
            self.style.isolines = count
            self.events.style.emit()

    def set_shell_coloring(self, coloring: str) -> None:
        if coloring not in SHELL_COLORINGS:
            raise ValueError(f"colouring must be one of {SHELL_COLORINGS}")
        if coloring != self.style.shell_coloring:
            self.style.shell_coloring = coloring
            self.events.style.emit()

    def set_render_style(self, style: str) -> None:
        if style not in RENDER_STYLES:
            raise ValueError(f"render style must be one of {RENDER_STYLES}")
        if style != self.style.render:
            self.style.render = style
            self.events.style.emit()

    def vector_coloring(self) -> str:
        """The colouring of 3D modes in effect: the chosen one, or for "auto" the
        magnitude on meshes with sharp features and the normal component elsewhere
        (see :mod:`modalviewer.viewer.mode_scalar`)."""
        if self.style.shell_coloring != "auto":
            return self.style.shell_coloring
        if self._derived.auto_coloring is None:
            self._derived.auto_coloring = default_vector_coloring(self.mesh)
        return self._derived.auto_coloring

    def set_colorbar(self, on: bool) -> None:
        if bool(on) != self.style.colorbar:
            self.style.colorbar = bool(on)
            self.events.style.emit()

    def set_animation(self, **changes) -> None:
        """playing (only a mode can play), amplitude (0..100), speed (1..100)."""
        anim = self.animation
        new = Animation(
            playing=bool(changes.get("playing", anim.playing)) and self.display.kind == "mode",
            amplitude=int(np.clip(changes.get("amplitude", anim.amplitude), 0, 100)),
            speed=int(np.clip(changes.get("speed", anim.speed), 1, 100)),
        )
        if new != anim:
            self.animation = new
            self.events.animation.emit()

    def set_scale_range(self, t_range: tuple[float, float] | None) -> None:
        """The scale range (t1, t2) of signatures and distances; None for the default."""
        if t_range is not None:
            t1, t2 = (float(t) for t in t_range)
            if not 0 < t1 < t2:
                raise ValueError("the scale range needs 0 < t1 < t2")
            t_range = (t1, t2)
        if t_range != self.t_range:
            self.t_range = t_range
            self._derived.distance.clear()
            self._sync_threshold()
            self.events.scale_range.emit()
            if self.display.kind in ("distance", "signature"):
                self.events.display.emit()

    def set_camera(self, camera: dict | None) -> None:
        """Set the camera (position, focal_point, view_up, parallel_scale); the scene
        applies it.  The scene also stores the user's camera here before a session is
        saved."""
        self.camera = camera
        self.events.camera.emit()

    # ---------------------------------------------------------- display
    def set_display(self, **changes) -> None:
        """Change what is shown; fields of :class:`Display`.  Validated before storing."""
        new = replace(self.display, **changes)
        if new.kind not in DISPLAY_KINDS:
            raise ValueError(f"display kind must be one of {DISPLAY_KINDS}")
        if new.distance_kind not in DISTANCE_KINDS:
            raise ValueError(f"distance kind must be one of {tuple(DISTANCE_KINDS)}")
        if new.distance_display not in DISTANCE_DISPLAYS:
            raise ValueError(f"distance display must be one of {DISTANCE_DISPLAYS}")
        if new.kind == "mode":
            spec = self.spectrum(new.operator)
            if spec is None:
                raise ValueError(f"no spectrum of {new.operator!r} has been computed")
            new = replace(new, mode=int(np.clip(new.mode, 0, spec.k - 1)))
        new = replace(
            new,
            threshold=float(np.clip(new.threshold, 1e-4, 1.0)),
            signature_sample=int(np.clip(new.signature_sample, 0, 99)),
        )
        if new == self.display:
            return
        self.display = new
        self._sync_threshold(set_by_user="threshold" in changes)
        if new.kind != "mode" and self.animation.playing:
            self.animation = replace(self.animation, playing=False)
            self.events.animation.emit()
        self.events.display.emit()

    def show_mode(self, index: int, operator: str | None = None) -> None:
        op = operator or self.display.operator or self._first_computed()
        self.set_display(kind="mode", operator=op, mode=index)

    def first_nonzero_mode(self, operator: str) -> int:
        spec = self.spectrum(operator)
        if spec is None:
            return 0
        nonzero = ~spec.zero_mode_mask()
        return int(np.argmax(nonzero)) if nonzero.any() else 0

    def _first_computed(self) -> str | None:
        ops = self.operators_computed()
        return ops[0] if ops else None

    @property
    def picked_file_vertex(self) -> int | None:
        """The picked vertex's number in the file (what the viewer shows and sessions
        store); :attr:`picked` is the mesh's (compact) index the computations use."""
        if self.picked is None or self.mesh is None:
            return None
        return self.mesh.file_vertex(self.picked)

    def set_pick_file_vertex(self, file_index: int | None) -> None:
        """Pick vertex ``file_index`` of the file (MeshError, a ValueError, for one no
        face uses or the file does not have)."""
        if file_index is not None:
            if self.mesh is None:
                raise ValueError("no mesh is loaded")
            file_index = self.mesh.mesh_vertex(file_index)
        self.set_pick(file_index)

    def set_pick(self, vertex: int | None) -> None:
        """Pick mesh vertex ``vertex`` (the mesh's index, as a click finds it; see
        :meth:`set_pick_file_vertex` for the file's numbers)."""
        if vertex is not None:
            if self.mesh is None:
                raise ValueError("no mesh is loaded")
            vertex = int(vertex)
            if not 0 <= vertex < self.mesh.n_vertices:
                raise ValueError(f"Vertex {vertex} does not exist (0..{self.mesh.n_vertices - 1}).")
        if vertex != self.picked:
            self.picked = vertex
            self._sync_threshold()
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

    def shows_preview(self) -> bool:
        """True if the display is made of a preview spectrum (every title and legend of
        the picture then says "preview")."""
        spec = self.spectrum(self.display_operator())
        return spec is not None and spec.is_preview

    def is_coarse(self, operator: str | None) -> bool:
        """True if the spectrum shown for ``operator`` was computed coarse-to-fine (on a
        decimated copy, carried to this mesh: approximate)."""
        key = self._latest.get(operator) if operator else None
        return key is not None and key.coarse and key in self.spectra

    def approximation_mark(self, operator: str | None) -> str:
        """ " (preview)", " (coarse-to-fine)" or "": what titles and lists add to the
        spectrum shown for ``operator`` when it is an approximation."""
        spec = self.spectrum(operator)
        if spec is not None and spec.is_preview:
            return " (preview)"
        if self.is_coarse(operator):
            return " (coarse-to-fine)"
        return ""

    def display_mark(self) -> str:
        """:meth:`approximation_mark` of the spectrum the picture is made of."""
        return self.approximation_mark(self.display_operator())

    def preview_note(self, operator: str | None) -> str:
        """ " (preview spectrum; the exact one follows)", " (preview spectrum)" or "" for
        the spectrum shown for ``operator``."""
        spec = self.spectrum(operator)
        if spec is None:
            return ""
        if not spec.is_preview:
            return " (coarse-to-fine spectrum)" if self.is_coarse(operator) else ""
        if self.exact_follows(operator):
            return " (preview spectrum; the exact one follows)"
        return " (preview spectrum)"

    # ---------------------------------------------------- derived values
    def has_signatures(self, operator: str) -> bool:
        """Whether ``operator``'s spectrum exists and has non-zero modes (signatures
        leave zero modes out)."""
        spec = self.spectrum(operator)
        return spec is not None and not spec.zero_mode_mask().all()

    def table(self, operator: str) -> SignatureTable:
        """The signature table of ``operator``'s spectrum over the current scale range."""
        spec = self.spectrum(operator)
        if spec is None:
            raise ValueError(f"no spectrum of {operator!r} has been computed")
        key = (operator, id(spec), self.t_range)
        table = self._derived.tables.get(key)
        if table is None:
            table = SignatureTable(spec, t_range=self.t_range)
            self._derived.tables[key] = table
        return table

    def distance_map(self, kind: str | None = None) -> np.ndarray | None:
        """Distance of ``kind`` from the picked vertex, or None if a spectrum is missing."""
        kind = kind or self.display.distance_kind
        operator = operator_for_distance(kind)
        spec = self.spectrum(operator)
        if self.picked is None or spec is None or spec.zero_mode_mask().all():
            return None
        key = (kind, self.picked, self.t_range, id(self.spectrum(operator)))
        d = self._derived.distance.get(key)
        if d is None:
            d = self.table(operator).distance_from(self.picked)
            self._derived.distance = {key: d}
        return d

    def threshold_value(self, d: np.ndarray | None = None) -> float | None:
        """The absolute threshold of the display's distance (fraction x largest)."""
        d = self.distance_map() if d is None else d
        if d is None:
            return None
        return self.display.threshold * float(d.max())

    def vertex_areas(self) -> np.ndarray:
        """(n,) lumped vertex areas: shares "of the surface" are shares of its area (on a
        mesh of uneven density the vertices' share is not: 18.8 % of a cow's vertices
        held 5.7 % of its area)."""
        if self._derived.vertex_areas is None:
            self._derived.vertex_areas = lumped_masses(self.mesh)
        return self._derived.vertex_areas

    def surface_share(self, d: np.ndarray, value: float) -> float:
        """The share (0..1) of the surface's area where ``d`` is at most ``value``."""
        areas = self.vertex_areas()
        return float(areas[d <= value].sum() / areas.sum())

    @property
    def share_target(self) -> float:
        """The share (0..1) of the surface threshold maps mark similar: the one last set,
        :data:`DEFAULT_THRESHOLD_SHARE` at first."""
        return self._share_target

    def threshold_share(self) -> float | None:
        """The share (0..1) of the surface the threshold map on screen marks similar, or
        None without one."""
        d = self.distance_map()
        if self.display.distance_display != "threshold" or d is None:
            return None
        return self.surface_share(d, self.threshold_value(d))

    def _map_identity(self) -> tuple | None:
        """What the distance map on screen is made of (kind, vertex, scales, spectrum)."""
        spec = self.spectrum(operator_for_distance(self.display.distance_kind))
        if spec is None or self.picked is None:
            return None
        return (self.display.distance_kind, self.picked, self.t_range, id(spec))

    def _sync_threshold(self, set_by_user: bool = False) -> None:
        """Keep a threshold map's share of the surface when its distances change.

        With ``threshold_by_share``, a threshold map on screen that the threshold was not
        set for (another vertex, kind, scale range or spectrum, or a first map) gets the
        threshold that marks the share last set (:data:`DEFAULT_THRESHOLD_SHARE` at
        first); the distances are so
        skewed that one fraction of the largest marks 95 % from one vertex and 10 % from
        another.  A threshold set by the user (or any, by value; also one set before its
        map is on screen, as ``show_distance(threshold=...)`` does) sets that share.
        Emits nothing: the caller's event redraws."""
        d = self.display
        on_screen = d.kind == "distance" and d.distance_display == "threshold"
        dist = self.distance_map() if on_screen else None  # no distances for other pictures
        if dist is None:
            # (a request's "display unchanged" test must not see a change here); a
            # fraction set for a map still to come is kept for it
            self._fraction_set |= set_by_user
            return
        identity = self._map_identity()
        if set_by_user or self._fraction_set or not d.threshold_by_share:
            self._fraction_set = False
            self._share_target = self.surface_share(dist, d.threshold * float(dist.max()))
        elif identity != self._share_map:
            self.display = replace(d, threshold=self.threshold_for_share(self._share_target, dist))
        self._share_map = identity

    def threshold_for_share(self, share: float, d: np.ndarray | None = None) -> float:
        """The threshold fraction that marks ``share`` (0..1) of the surface similar."""
        d = self.distance_map() if d is None else d
        if d is None or d.max() <= 0:
            return float(share)
        order = np.argsort(d, kind="stable")
        areas = self.vertex_areas()[order]
        cumulative = np.cumsum(areas) / areas.sum()
        i = int(np.searchsorted(cumulative, float(np.clip(share, 0.0, 1.0)) - 1e-12))
        value = float(d[order[min(i, len(order) - 1)]])
        return float(np.clip(value / float(d.max()), 1e-4, 1.0))

    def mode_fields(self, spec: Spectrum, j: int) -> tuple[np.ndarray, np.ndarray]:
        """(scalar to colour (n,), displacement (n, 3) scaled to a peak of 1) of mode j."""
        phi = spec.mode(j)
        if spec.is_vector:
            coloring = self.vector_coloring()
            if coloring == "normal" and self._derived.smooth_normals is None:
                self._derived.smooth_normals = smoothed_normals(self.mesh)
            scalar = vector_mode_scalar(phi, self._derived.smooth_normals, coloring)
            disp = phi
        else:
            scalar = phi
            disp = phi[:, None] * self.normals
        peak = float(np.max(np.linalg.norm(disp, axis=1))) or 1.0
        return scalar, disp / peak

    def curvature(self) -> np.ndarray:
        if self._derived.curvature is None:
            self._derived.curvature = total_curvature(self.mesh)
        return self._derived.curvature

    def field(self) -> Field | None:
        """The picture the display asks for, or None if it cannot be drawn (yet)."""
        if self.mesh is None:
            return None
        d = self.display
        n = self.mesh.n_vertices
        plain = Field(np.zeros(n), "plain")
        mark = self.display_mark()
        if d.kind == "mode":
            spec = self.spectrum(d.operator)
            if spec is None:
                return plain
            j = int(np.clip(d.mode, 0, spec.k - 1))
            scalar, disp = self.mode_fields(spec, j)
            magnitude = spec.is_vector and self.vector_coloring() == "magnitude"
            return Field(
                scalar,
                "sequential" if magnitude else "diverging",
                isolines=self.style.isolines,
                displacement=disp,
                title=f"{operator_info(d.operator).short_label} mode {j}{mark}",
                legend=self.legend(),
            )
        if d.kind == "distance":
            dist = self.distance_map()
            if dist is None:
                return plain
            name = DISTANCE_KINDS[d.distance_kind]
            if d.distance_display == "threshold":
                thr = self.threshold_value(dist)
                return Field(
                    dist,
                    "threshold",
                    threshold=thr,
                    title=f"{name} < {thr:.3g}{mark}",
                    legend=self.legend(),
                    share_similar=self.surface_share(dist, thr),
                )
            return Field(dist, "sequential", title=name + mark, legend=self.legend())
        if d.kind == "signature":
            operator = operator_for_distance(d.distance_kind)
            spec = self.spectrum(operator)
            if not self.has_signatures(operator):
                return plain
            t = self.signature_time()
            _, values = signature(spec, [t])
            return Field(
                values[:, 0],
                "sequential",
                isolines=self.style.isolines,
                title=f"signature t = {t:.3g}{mark}",
                legend=self.legend(),
            )
        if d.kind == "curvature":
            curvature = self.curvature()
            hi = float(np.percentile(curvature, 98)) or 1.0
            return Field(
                curvature,
                "sequential",
                clim=(0.0, hi),
                title="curvature",
                legend=self.legend(),
            )
        return plain

    def signature_time(self) -> float:
        table = self.table(operator_for_distance(self.display.distance_kind))
        return float(
            table.times[int(np.clip(self.display.signature_sample, 0, len(table.times) - 1))]
        )

    # ------------------------------------------------------------- words
    def legend(self) -> str:
        """One or two lines naming what the surface shows, with its numbers."""
        d = self.display
        if self.mesh is None or d.kind == "none":
            return ""
        if d.kind == "mode":
            spec = self.spectrum(d.operator)
            if spec is None:
                return ""
            j = int(np.clip(d.mode, 0, spec.k - 1))
            lam = float(spec.eigenvalues[j])
            zero = spec.zero_mode_mask()[j]
            value = "0 (zero mode)" if zero else f"{lam:.4g}"
            if spec.is_preview:
                value += f" (preview; estimated error {percent_text(spec.estimated_error)})"
            elif self.is_coarse(d.operator):
                value += " (coarse-to-fine: approximate)"
            colours = "blue +, white 0, orange -"
            if spec.is_vector and self.vector_coloring() == "magnitude":
                colours = "white 0 to red: displacement magnitude"
            elif spec.is_vector:
                colours += " (normal component, smoothed normals)"
            return f"{operator_info(d.operator).label}, mode {j}: lambda = {value}\n{colours}"
        if d.kind == "distance":
            name = DISTANCE_KINDS[d.distance_kind]
            dist = self.distance_map()
            if dist is None:
                return f"{name}: {self._missing_distance_reason(d.distance_kind)}"
            source = f"from vertex {self.picked_file_vertex}"
            source += self.preview_note(operator_for_distance(d.distance_kind))
            if d.distance_display == "threshold":
                thr = self.threshold_value(dist)
                share = 100.0 * self.surface_share(dist, thr)
                return f"blue: {name.lower()} < {thr:.3g}, {share:.1f} % of the surface\n{source}"
            t1, t2 = self.scale_limits()
            return (
                f"{name} {source}: white 0 to red {float(dist.max()):.3g}\n"
                f"scales t = {t1:.3g} .. {t2:.3g}"
            )
        if d.kind == "signature":
            operator = operator_for_distance(d.distance_kind)
            if not self.has_signatures(operator):
                return ""
            word = {"vibration": "Vibration", "feature": "Feature", "hks": "Heat kernel"}
            return f"{word[d.distance_kind]} signature at t = {self.signature_time():.3g}"
        if d.kind == "curvature":
            return "Curvature sqrt(k1^2 + k2^2), white 0 to red (98th percentile)"
        return ""

    def _missing_distance_reason(self, kind: str) -> str:
        if self.picked is None:
            return "pick a vertex"
        spec = self.spectrum(operator_for_distance(kind))
        if spec is None:
            return f"needs the {operator_info(operator_for_distance(kind)).label} spectrum"
        return "the spectrum has no non-zero modes; compute more modes"

    def scale_limits(self) -> tuple[float, float]:
        """(t1, t2) the distances and signatures use: the chosen range or the default."""
        table = self.table(operator_for_distance(self.display.distance_kind))
        return float(table.times[0]), float(table.times[-1])

    def summary(self) -> str:
        """The status line: the current display's live numbers, on one line."""
        if self.mesh is None:
            return "Open a mesh to begin (File > Open, Ctrl+O)."
        text = self.legend().replace("\n", "; ")
        if not text:
            m = self.mesh
            text = f"{_plural(m.n_vertices, 'vertex')}, {_plural(m.n_faces, 'face')}"
            if self.computing and not self.spectra:
                names = sorted({operator_info(key.operator).label for key in self.computing})
                text += f"; computing {', '.join(names)} (Esc cancels)"
                if self.picked is not None:
                    text += f"; the map of vertex {self.picked_file_vertex} follows"
            elif not self.spectra:
                text += "; compute a spectrum (Ctrl+R) or click the surface"
        return text
