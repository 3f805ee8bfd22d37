"""Values computed from the viewer's state and kept until it changes (no Qt, no VTK).

:class:`DerivedValues` (``state.derived``): normals, colour ranges, curvature, areas,
signature tables, the pick's distance map and :meth:`DerivedValues.field`, the picture
the scene draws.  Each value remembers what it was computed from (mesh, spectrum object,
pick, scale range) and is recomputed when that changed, so no reader gets a stale value
whatever order the event callbacks run in; the state's events release the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.laplacian import lumped_masses, total_curvature, vertex_normals
from ..core.operators import (
    DISTANCE_KINDS,
    operator_for_distance,
    operator_info,
    signature_kind,
)
from ..core.signatures import (
    SignatureTable,
    default_energies,
    default_times,
    signature,
    wks_sigma,
)
from ..core.spectrum import Spectrum
from ..core.truncation import TRUNCATION_LEVEL, k_for_truncation, truncation_error
from . import wording
from .camera import DEFAULT_UP, detect_up
from .color_scale import SPREAD_SHARE, crowded_share, robust_limit, spread_knots
from .mode_scalar import smoothed_normals, vector_mode_scalar

TIE_TOLERANCE = 1e-7  # distances this close (share of the largest) are marked together


@dataclass
class Field:
    """A per-vertex picture derived from the state, ready for the scene to draw."""

    values: np.ndarray
    colormap: str  # "diverging", "sequential" (white to red), "threshold", "plain"
    isolines: int = 0
    displacement: np.ndarray | None = None  # (n, 3) the mode's shape, largest length 1
    clim: tuple[float, float] | None = None
    title: str = ""
    legend: str = ""
    share_similar: float | None = None
    threshold: float | None = None  # "threshold": values up to it are blue
    deformation: float = 0.0  # drawn at rest + deformation * displacement
    ghost: bool = False  # the rest shape faint behind the displaced surface
    clipped: tuple[bool, bool] = (False, False)  # values beyond clim's (low, high)
    color_range: str = ""  # the range's rule
    scale: tuple[np.ndarray, np.ndarray] | None = None  # a spread range's knots


class DerivedValues:
    """The cached values computed from ``state``; see the module docstring."""

    def __init__(self, state) -> None:
        self.state = state
        self._kept: dict = {}  # name -> (inputs, value): see _value
        state.events.mesh.connect(lambda: self._kept.clear())
        state.events.spectra.connect(self._drop_stale_spectra)

    # ---------------------------------------------------------- caches
    def _value(self, name, inputs: tuple, compute=None):
        """The value kept as ``name`` if computed from ``inputs`` (the same objects, or
        equal plain values), else ``compute()`` kept (None without ``compute``)."""
        kept, plain = self._kept.get(name), (str, int, float, tuple)
        if kept is not None and len(kept[0]) == len(inputs):
            same = zip(kept[0], inputs, strict=True)
            if all(a is b or (isinstance(a, plain) and a == b) for a, b in same):
                return kept[1]
        if compute is None:
            return None
        self._kept[name] = (inputs, value := compute())
        return value

    def _drop_stale_spectra(self, operator: str = "") -> None:
        """Release the values made of spectra the state no longer holds."""
        held = list(self.state.spectra.values())
        for name, (inputs, _) in list(self._kept.items()):
            if any(isinstance(x, Spectrum) and all(x is not s for s in held) for x in inputs):
                del self._kept[name]

    def _mesh_value(self, name: str, compute):
        """The per-mesh value ``name``, computed by ``compute(mesh)`` once per mesh."""
        mesh = self.state.mesh
        return self._value(name, (mesh,), lambda: compute(mesh))

    def keep_table(self, spec: Spectrum, table: SignatureTable) -> None:
        """Keep ``table``, built with ``spec`` (over ``table.t_range``), for reuse."""
        self._kept["table", spec.operator, table.kind] = ((spec, table.t_range), table)

    # ------------------------------------------------------- per mesh
    @property
    def normals(self) -> np.ndarray | None:
        """(n, 3) area-weighted vertex normals of the mesh, or None without one."""
        if self.state.mesh is None:
            return None
        return self._mesh_value("normals", vertex_normals)

    def smoothed_normals(self) -> np.ndarray:
        """(n, 3) smoothed normals the normal component of a 3D mode is taken against."""
        return self._mesh_value("smooth_normals", smoothed_normals)

    def vector_coloring(self) -> str:
        """How 3D modes are coloured: "normal" (component) or "magnitude"."""
        coloring = self.state.style.shell_coloring
        return "magnitude" if coloring == "deformed" else coloring

    def amplitude_length(self) -> float:
        """A displaced mode's largest displacement: ``animation.amplitude`` % of a quarter
        of the bounding-box diagonal."""
        mesh = self.state.mesh
        if mesh is None:
            return 0.0
        return self.state.animation.amplitude / 100.0 * 0.25 * mesh.bounding_box_diagonal

    def deformation(self) -> float:
        """:meth:`amplitude_length` for a 3D mode shown "deformed", else 0."""
        state = self.state
        d = state.display
        if d.kind != "mode" or state.style.shell_coloring != "deformed":
            return 0.0
        spec = state.spectrum(d.operator)
        return self.amplitude_length() if spec is not None and spec.is_vector else 0.0

    def color_range(self, values: np.ndarray, colormap: str) -> tuple[tuple, tuple, str]:
        """(clim, clipped (low, high), rule applied) of ``values`` drawn with ``colormap``
        under ``style.color_range``; "auto" is symmetric for modes (every mode), else
        robust, or "spread" where a tenth of the robust scale would cover more than
        :data:`.color_scale.SPREAD_SHARE` of the surface."""
        style, values = self.state.style, np.asarray(values, dtype=np.float64)
        rule = style.color_range
        may_spread = rule == "auto" and self.state.display.kind != "mode"  # modes: one rule
        if rule == "auto":
            rule = "robust" if may_spread else "symmetric"
        if rule == "spread":
            if colormap == "sequential" and values.size:
                return (float(values.min()), float(values.max())), (False, False), rule
            rule = "robust"
        if rule == "limits" and style.color_limits is not None:
            lo, hi = style.color_limits
        else:
            if rule == "robust":
                a = robust_limit(values, self.vertex_areas())
            else:
                rule = "symmetric"
                a = float(np.max(np.abs(values))) if values.size else 0.0
            a = a or 1.0
            lo, hi = (-a, a) if colormap == "diverging" else (0.0, a)
        if (
            may_spread
            and colormap == "sequential"
            and values.size
            and crowded_share(values, self.vertex_areas(), (lo, hi)) > SPREAD_SHARE
        ):
            return (float(values.min()), float(values.max())), (False, False), "spread"
        tol = 1e-12 * max(abs(lo), abs(hi))
        clipped = (
            bool(values.size and values.min() < lo - tol),
            bool(values.size and values.max() > hi + tol),
        )
        return (float(lo), float(hi)), clipped, rule

    def scaled(self, field: Field) -> Field:
        """``field`` with its colour range and, on a spread range, its knots."""
        field.clim, field.clipped, field.color_range = self.color_range(
            field.values, field.colormap
        )
        if field.color_range == "spread":
            field.scale = spread_knots(field.values, self.vertex_areas())
        return field

    def _ranged(self, field: Field) -> Field:
        """``field`` with its colour range, and the range named in its legend."""
        self.scaled(field)
        note = wording.range_note(field.color_range, field.clim, field.clipped)
        field.legend = f"{field.legend}\n{note}" if field.legend else note
        return field

    def curvature(self) -> np.ndarray:
        """(n,) total curvature sqrt(k1^2 + k2^2) of the mesh."""
        return self._mesh_value("curvature", total_curvature)

    def vertex_areas(self) -> np.ndarray:
        """(n,) lumped vertex areas: shares "of the surface" are of its area, not vertices."""
        return self._mesh_value("vertex_areas", lumped_masses)

    # ----------------------------------------------------- signatures
    def has_signatures(self, operator: str) -> bool:
        """Whether ``operator``'s spectrum has non-zero modes (signatures omit zero modes)."""
        spec = self.state.spectrum(operator)
        return spec is not None and not spec.zero_mode_mask().all()

    def table(self, operator: str, kind: str = "heat") -> SignatureTable:
        """The ``kind`` ("heat" or "wks") signature table of ``operator`` over the scale range."""
        spec = self.state.spectrum(operator)
        if spec is None:
            raise ValueError(f"no spectrum of {operator!r} has been computed")
        t_range = self.state.t_range
        return self._value(
            ("table", operator, kind),
            (spec, t_range),
            lambda: SignatureTable(spec, t_range=t_range, kind=kind),
        )

    def kind_table(self, kind: str | None = None) -> SignatureTable:
        """The signature table distance ``kind`` (the display's by default) uses."""
        kind = kind or self.state.display.distance_kind
        return self.table(operator_for_distance(kind), signature_kind(kind))

    def wave(self) -> bool:
        """Whether the display's distance kind is a wave kernel's (scales are energies)."""
        return signature_kind(self.state.display.distance_kind) == "wks"

    def signature_time(self) -> float:
        """The signature display's scale: the typed one, or the sample's."""
        display = self.state.display
        if display.signature_time is not None:
            return float(display.signature_time)
        table = self.kind_table()
        return float(table.times[int(np.clip(display.signature_sample, 0, len(table.times) - 1))])

    def nearest_sample(self, t: float) -> int:
        """The table's scale nearest to ``t`` in log (the slider's place for a typed t)."""
        table = self.kind_table()
        return int(np.argmin(np.abs(np.log(table.times) - np.log(float(t)))))

    def signature_values(self, operator: str, t: float, kind: str = "heat") -> np.ndarray:
        """(n,) the signature of ``operator`` at scale (or "wks" energy) ``t``; with
        ``style.log_signature`` its log10 over its smallest value."""
        spec = self.state.spectrum(operator)
        if kind == "wks":
            sigma = wks_sigma(self.table(operator, kind).times)
            _, values = signature(spec, kind="wks", energies=[t], sigma=sigma)
        else:
            _, values = signature(spec, [t])
        values = values[:, 0]
        if self.state.style.log_signature:
            positive = values[values > 0]
            floor = float(positive.min()) if positive.size else 1.0
            values = np.log10(np.maximum(values, floor) / floor)
        return values

    def truncation(self, operator: str | None = None, t: float | None = None):
        """(estimated truncation error, k suggested) of ``operator``'s signature at ``t``
        (defaults: the display's; :mod:`modalviewer.core.truncation`).  None without
        signatures, and for the wave kernel (the estimate is the heat kernel's)."""
        if operator is None:
            if self.wave():
                return None
            operator = operator_for_distance(self.state.display.distance_kind)
        if not self.has_signatures(operator):
            return None
        spec = self.state.spectrum(operator)
        t = self.signature_time() if t is None else float(t)

        def estimate():
            error = float(truncation_error(spec, [t])[0])
            return error, k_for_truncation(spec, t) if error > TRUNCATION_LEVEL else spec.k

        return self._value(("truncation", operator, t), (spec,), estimate)

    # ------------------------------------------- the picked vertex's curve
    def curve_key(self) -> tuple | None:
        """(operator, spectrum id, vertex, scale range) of the picked vertex's curve; None
        without one and for the wave kernel (not summed over all modes)."""
        state = self.state
        operator = operator_for_distance(state.display.distance_kind)
        if state.picked is None or not self.has_signatures(operator) or self.wave():
            return None
        return (operator, id(state.spectrum(operator)), state.picked, state.t_range)

    def curve(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(scales, values) of the picked vertex's signature at the display kind's table's
        scales; None without a pick or signatures."""
        state = self.state
        operator = operator_for_distance(state.display.distance_kind)
        if state.picked is None or not self.has_signatures(operator):
            return None
        table = self.kind_table()
        spec, vertices = state.spectrum(operator), [state.picked]
        if table.kind == "wks":
            times, values = signature(spec, kind="wks", energies=table.times, vertices=vertices)
        else:
            times, values = signature(spec, table.times, vertices=vertices)
        return times, values[0]

    def curve_truncation(self) -> float | None:
        """The curve's truncation error at its smallest scale (the largest), or None."""
        key = self.curve_key()
        if key is None:
            return None
        return self.truncation(key[0], float(self.table(key[0]).times[0]))[0]

    def exact_curve(self) -> np.ndarray | None:
        """(T,) the curve summed over all modes, once
        :meth:`.model.ViewerModel.request_exact_curve` has computed it, else None."""
        key = self.curve_key()
        return None if key is None else self._value("exact curve", (key,))

    def keep_exact_curve(self, key: tuple, values: np.ndarray) -> None:
        """Keep the exact curve computed for ``key`` (:meth:`curve_key`)."""
        self._kept["exact curve"] = ((key,), np.asarray(values))

    def up_axis(self) -> str:
        """The chosen up axis, else :func:`.camera.detect_up`'s, else +Y."""
        if self.state.up_axis is not None:
            return self.state.up_axis
        if self.state.mesh is None:
            return DEFAULT_UP
        detected = self._mesh_value("up", lambda m: detect_up(m.vertices, m.faces))
        return detected or DEFAULT_UP

    def default_range(self) -> tuple[float, float] | None:
        """The display kind's default scale range (an empty field's); None without it."""
        spec = self.state.spectrum(operator_for_distance(self.state.display.distance_kind))
        if spec is None:
            return None
        times = default_energies(spec) if self.wave() else default_times(spec)
        return float(times[0]), float(times[-1])

    def scale_limits(self) -> tuple[float, float]:
        """(t1, t2) the distances and signatures use: the chosen range or the default."""
        table = self.kind_table()
        return float(table.times[0]), float(table.times[-1])

    # ------------------------------------------------------ distances
    def distance_map(self, kind: str | None = None) -> np.ndarray | None:
        """Distance of ``kind`` (default: the display's) from the pick, or None."""
        state = self.state
        kind = kind or state.display.distance_kind
        spec = state.spectrum(operator_for_distance(kind))
        if state.picked is None or spec is None or spec.zero_mode_mask().all():
            return None
        inputs = (kind, state.picked, state.t_range, spec)
        return self._value(
            "distance", inputs, lambda: self.kind_table(kind).distance_from(inputs[1])
        )

    def map_identity(self) -> tuple | None:
        """(kind, vertex, scale range, spectrum id) of the display's map, or None."""
        state = self.state
        spec = state.spectrum(operator_for_distance(state.display.distance_kind))
        if spec is None or state.picked is None:
            return None
        return (state.display.distance_kind, state.picked, state.t_range, id(spec))

    def threshold_value(self, d: np.ndarray | None = None) -> float | None:
        """The absolute threshold of the display's distance (fraction x largest)."""
        d = self.distance_map() if d is None else d
        return None if d is None else self.state.display.threshold * float(d.max())

    def map_fraction(self, d: np.ndarray) -> float:
        """The threshold fraction for ``d``: the display's, or with ``keep_share`` while no
        threshold map is drawn (the state matches it only then), the kept share's."""
        display = self.state.display
        if display.keep_share and display.distance_display != "threshold":
            return self.threshold_for_share(display.threshold_share, d)
        return display.threshold

    def surface_share(self, d: np.ndarray, value: float) -> float:
        """The share (0..1) of the surface's area where ``d`` is at most ``value``."""
        areas = self.vertex_areas()
        return float(areas[d <= value].sum() / areas.sum())

    def marked_share(self) -> float | None:
        """The share of the surface the threshold map on screen marks, or None."""
        d = self.distance_map()
        if self.state.display.distance_display != "threshold" or d is None:
            return None
        return self.surface_share(d, self.threshold_value(d))

    def threshold_for_share(self, share: float, d: np.ndarray | None = None) -> float:
        """The fraction marking ``share`` of the surface (a little more where distances
        equal to :data:`TIE_TOLERANCE` straddle it: all are marked)."""
        d = self.distance_map() if d is None else d
        if d is None or d.max() <= 0:
            return float(share)
        order = np.argsort(d, kind="stable")
        areas = self.vertex_areas()[order]
        cumulative = np.cumsum(areas) / areas.sum()
        i = int(np.searchsorted(cumulative, float(np.clip(share, 0.0, 1.0)) - 1e-12))
        value = float(d[order[min(i, len(order) - 1)]])
        # distances equal up to round-off (a region where the signatures all but vanish
        # at every scale has one value to 1e-9) are marked all or none: a threshold inside
        # them would mark them at random (speckles)
        sorted_d = d[order]
        j = int(np.searchsorted(sorted_d, value + TIE_TOLERANCE * float(d.max()), "right"))
        value = float(sorted_d[max(j - 1, 0)])
        # a few ulps up: the map compares d with fraction * max(d), whose rounding could
        # otherwise fall just below ``value`` and leave its vertex out of the share
        fraction = value / float(d.max()) * (1.0 + 4.0 * np.finfo(float).eps)
        return float(np.clip(fraction, 1e-4, 1.0))

    # -------------------------------------------------------- pictures
    def mode_fields(self, spec: Spectrum, j: int) -> tuple[np.ndarray, np.ndarray]:
        """(scalar (n,), displacement (n, 3) of peak 1) of mode j."""
        phi = spec.mode(j)
        if not spec.is_vector:  # a scalar mode displaces the surface along its normals
            scalar, disp = phi, phi[:, None] * self.normals
        else:
            coloring = self.vector_coloring()
            normals = self.smoothed_normals() if coloring == "normal" else None
            scalar, disp = vector_mode_scalar(phi, normals, coloring), phi
        peak = float(np.max(np.linalg.norm(disp, axis=1))) or 1.0
        return scalar, disp / peak

    def field(self) -> Field | None:
        """The picture the display asks for, or None if it cannot be drawn (yet)."""
        state = self.state
        if state.mesh is None:
            return None
        d, isolines = state.display, state.style.isolines
        plain = Field(np.zeros(state.mesh.n_vertices), "plain")
        mark, legend = wording.display_mark(state), wording.legend(state)
        if d.kind == "mode":
            spec = state.spectrum(d.operator)
            if spec is None:
                return plain
            j = int(np.clip(d.mode, 0, spec.k - 1))
            scalar, disp = self.mode_fields(spec, j)
            magnitude = spec.is_vector and self.vector_coloring() == "magnitude"
            deformation = self.deformation()
            title = f"{operator_info(d.operator).short_label} mode {j}{mark}"
            colormap = "sequential" if magnitude else "diverging"
            return self._ranged(
                Field(scalar, colormap, isolines, disp, title=title, legend=legend,
                      deformation=deformation, ghost=state.style.ghost and deformation > 0)
            )  # fmt: skip
        if d.kind == "distance":
            dist = self.distance_map()
            if dist is None:
                return plain
            name = DISTANCE_KINDS[d.distance_kind]
            if d.distance_display != "threshold":
                return self._ranged(Field(dist, "sequential", title=name + mark, legend=legend))
            thr = self.threshold_value(dist)
            return Field(dist, "threshold", title=f"{name} < {thr:.3g}{mark}", legend=legend,
                         share_similar=self.surface_share(dist, thr), threshold=thr)  # fmt: skip
        if d.kind == "signature":
            operator = operator_for_distance(d.distance_kind)
            if not self.has_signatures(operator):
                return plain
            t = self.signature_time()
            values = self.signature_values(operator, t, signature_kind(d.distance_kind))
            title = f"signature {'E' if self.wave() else 't'} = {t:.3g}{mark}"
            return self._ranged(Field(values, "sequential", isolines, title=title, legend=legend))
        if d.kind == "curvature":
            return self._ranged(
                Field(self.curvature(), "sequential", title="curvature", legend=legend)
            )
        if d.kind == "field" and d.field in state.fields:
            values = state.fields[d.field]
            signed = float(values.min()) < 0.0 < float(values.max())
            colormap = "diverging" if signed else "sequential"
            return self._ranged(Field(values, colormap, isolines, title=d.field, legend=legend))
        return plain
