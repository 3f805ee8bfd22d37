"""The viewer's words: legends, the status line, notes and marks, and how a job ended
(no Qt, no VTK).  Marks and notes take the values they name; the legend and the status
line read the state and its derived values.  Nothing here changes or caches anything.
"""

from __future__ import annotations

import numpy as np

from ..core.mesh import _plural
from ..core.operators import (
    DISTANCE_KINDS,
    OPERATOR_INFO,
    distance_word,
    operator_for_distance,
    operator_info,
)
from ..core.pipeline import FLOOR_FACTOR
from ..core.robust import negative_cotan_weights
from ..core.spectrum import Spectrum
from ..core.truncation import TRUNCATION_LEVEL
from .color_scale import ROBUST_PERCENTILE
from .jobs import CANCELLED, DONE, Job, SpectrumJob


def percent_text(fraction: float) -> str:
    """A relative error as a short percentage: two significant digits below ten per cent,
    whole per cents above, "less than" below a hundredth of a per cent (more digits would
    show convergence, not error); no-break spaces keep number and sign together."""
    value = 100.0 * float(fraction)
    if 0 < value < 0.01:
        return "<\u00a00.01\u00a0%"
    return f"{value:.0f}\u00a0%" if value >= 10 else f"{value:.2g}\u00a0%"


def arrival_text(spec: Spectrum | None) -> str:
    """ "first 20 of 100 modes" while ``spec``'s modes are still arriving, else ""."""
    if spec is None or spec.k >= spec.modes_requested:
        return ""
    return f"first {spec.k} of {spec.modes_requested} modes"


def arrival_note(spec: Spectrum | None, computing: bool) -> str:
    """A sentence on a spectrum still arriving (``computing``) or stopped before its last
    modes; "" for a whole spectrum."""
    if not arrival_text(spec):
        return ""
    ready, asked = spec.k, spec.modes_requested
    if computing:
        return f"{ready} of {asked} modes ready; the others follow as they converge."
    return (
        f"Only {ready} of {asked} modes: the computation stopped before the others "
        "(Compute, Ctrl+R, computes them all)."
    )


def approximation_mark(spec: Spectrum | None, coarse: bool) -> str:
    """ " (coarse-to-fine)", " (first 20 of 100 modes)" or "": the titles' mark of an
    approximate (``coarse``) or incomplete spectrum."""
    marks = [m for m in ("coarse-to-fine" if coarse else "", arrival_text(spec)) if m]
    return f" ({'; '.join(marks)})" if marks else ""


def display_mark(state) -> str:
    """:func:`approximation_mark` of the spectrum the picture is made of."""
    op = state.display_operator()
    return approximation_mark(state.spectrum(op), state.is_coarse(op))


def approximation_note(spec: Spectrum | None, coarse: bool) -> str:
    """ " (coarse-to-fine spectrum)", " (from the first 20 of 100 modes)" or "" for a map
    or signature made of ``spec``."""
    arriving = arrival_text(spec)  # "" without a spectrum
    notes = ["coarse-to-fine spectrum"] if coarse and spec is not None else []
    notes += [f"from the {arriving}"] if arriving else []
    return f" ({'; '.join(notes)})" if notes else ""


def _approximation_note(state, kind: str) -> str:
    """:func:`approximation_note` of the spectrum distance ``kind`` is made of."""
    op = operator_for_distance(kind)
    return approximation_note(state.spectrum(op), state.is_coarse(op))


def missing_distance_reason(state, kind: str) -> str:
    """Why there is no distance map of ``kind``: what to do to get one."""
    if state.picked is None:
        return "pick a vertex"
    operator = operator_for_distance(kind)
    if state.spectrum(operator) is None:
        return f"needs the {operator_info(operator).label} spectrum"
    return "the spectrum has no non-zero modes; compute more modes"


def legend(state) -> str:
    """One or two lines naming what the surface shows, with its numbers."""
    derived, d = state.derived, state.display
    if state.mesh is None or d.kind == "none":
        return ""
    if d.kind == "mode":
        spec = state.spectrum(d.operator)
        if spec is None:
            return ""
        j = int(np.clip(d.mode, 0, spec.k - 1))
        zero = spec.zero_mode_mask()[j]
        value = "0 (zero mode)" if zero else f"{float(spec.eigenvalues[j]):.4g}"
        if state.is_coarse(d.operator):
            value += " (coarse-to-fine: approximate)"
        colours = "blue +, white 0, orange -"
        # the colours are the mode's own |Phi| (Mass-normalised), not the drawn
        # displacement, which the Amplitude scales: the legend says which
        magnitude = "white 0 to red: |Phi| per vertex (Mass-normalised mode)"
        if spec.is_vector and state.style.shell_coloring == "deformed":
            colours = f"deformed shape, {magnitude}"
            if state.style.ghost:
                colours += "; grey: rest shape"
        elif spec.is_vector and derived.vector_coloring() == "magnitude":
            colours = magnitude
        elif spec.is_vector:
            colours += " (normal component, smoothed normals)"
        return f"{operator_info(d.operator).label}, mode {j}: lambda = {value}\n{colours}"
    if d.kind == "distance":
        name = DISTANCE_KINDS[d.distance_kind]
        dist = derived.distance_map()
        if dist is None:
            return f"{name}: {missing_distance_reason(state, d.distance_kind)}"
        source = f"from vertex {state.picked_file_vertex}"
        source += _approximation_note(state, d.distance_kind)
        if d.distance_display == "threshold":
            thr = derived.threshold_value(dist)
            share = 100.0 * derived.surface_share(dist, thr)
            return f"blue: {name.lower()} < {thr:.3g}, {share:.1f} % of the surface\n{source}"
        t1, t2 = derived.scale_limits()
        scales = "energies E" if derived.wave() else "scales t"
        return (
            f"{name} {source}: white 0 to red {float(dist.max()):.3g}\n"
            f"{scales} = {t1:.3g} .. {t2:.3g}"
        )
    if d.kind == "signature":
        if not derived.has_signatures(operator_for_distance(d.distance_kind)):
            return ""
        word = distance_word(d.distance_kind).capitalize()
        at = "E" if derived.wave() else "t"
        text = f"{word} signature at {at} = {derived.signature_time():.3g}"
        text += _approximation_note(state, d.distance_kind)
        if state.style.log_signature:
            text += ", log10(S / smallest S)"
        spec = state.spectrum(operator_for_distance(d.distance_kind))
        note = truncation_note(derived.truncation(), spec.k)
        return f"{text}\n{note}" if note else text
    if d.kind == "curvature":
        return "Curvature sqrt(k1^2 + k2^2), white 0 to red"
    if d.kind == "field" and d.field in state.fields:
        values = state.fields[d.field]
        signed = float(values.min()) < 0.0 < float(values.max())
        colours = "blue +, white 0, orange -" if signed else "white to red"
        return f"{d.field}: {colours}"
    return ""


def range_note(rule: str, clim: tuple[float, float], clipped: tuple[bool, bool]) -> str:
    """The legend's line naming the colour range ``rule`` and the clipped ends."""
    lo, hi = clim
    if rule == "spread":
        return "colours spread by area: each tenth of the bar covers a tenth of the surface"
    text = {
        "robust": f"robust range: {ROBUST_PERCENTILE:g}th percentile of |value| by area",
        "limits": f"range: limits {lo:.3g} .. {hi:.3g}",
    }.get(rule, "range: the largest |value|")
    ends = [f"< {lo:.3g}"] * clipped[0] + [f"> {hi:.3g}"] * clipped[1]
    if ends:
        text += f" ({' and '.join(ends)} clipped)"
    return text


def negative_weights_note(state) -> str:
    """Advice to use the operator whose weights are never negative, where the mesh has
    negative cotan weights; else ""."""
    robust = next((info for info in OPERATOR_INFO.values() if info.nonnegative_weights), None)
    if state.mesh is None or robust is None:
        return ""
    count = negative_cotan_weights(state.mesh)
    if count == 0:
        return ""
    return (
        f"This mesh has {_plural(count, 'negative cotan weight')}: try the {robust.label}, "
        "whose weights are never negative."
    )


def truncation_note(truncation: tuple[float, int] | None, k: int) -> str:
    """The share of a signature of ``k`` modes truncation misses and the k bringing it
    below :data:`~modalviewer.core.truncation.TRUNCATION_LEVEL`, when above it; else ""."""
    if truncation is None or truncation[0] <= TRUNCATION_LEVEL:
        return ""
    error, needed = truncation
    return (
        f"truncation: about {percent_text(error)} of the signature is missing (k = "
        f"{k}; k = {needed} for < {percent_text(TRUNCATION_LEVEL)})"
    )


def summary(state) -> str:
    """The status line: the current display's live numbers, on one line."""
    if state.mesh is None:
        return "Open a mesh to begin (File > Open, Ctrl+O)."
    text = legend(state).replace("\n", "; ")
    if not text:
        m = state.mesh
        text = f"{_plural(m.n_vertices, 'vertex')}, {_plural(m.n_faces, 'face')}"
        if state.computing and not state.spectra:
            names = sorted({operator_info(key.operator).label for key in state.computing})
            text += f"; computing {', '.join(names)} (Esc cancels)"
            if state.picked is not None:
                text += f"; the map of vertex {state.picked_file_vertex} follows"
        elif not state.spectra:
            text += "; compute a spectrum (Ctrl+R) or click the surface"
    return text


def seconds_text(seconds: float) -> str:
    """About how long, in words: whole seconds below two minutes, then whole minutes."""
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"


# what the status line and ``modalviewer compute`` say of a solve that saved memory
OUT_OF_CORE_WORDS = "factor kept on disk"
FLOAT32_BASIS_WORDS = "Krylov basis in single precision"


def finished_text(job: SpectrumJob, spec: Spectrum) -> str:
    """A finished spectrum job's status line: the description and the solve's stored
    time (a solve and its reopening say the same), for a cache hit the reading time as
    well, so it does not read like a fresh solve."""
    fewer = fewer_modes_text(job, spec)
    solved = spec.parameters.get("seconds_total")
    if not isinstance(solved, (int, float)) or "transferred_from" in spec.parameters:
        solved = None
    if not spec.from_cache:
        return f"{job.description}{fewer} in {job.seconds if solved is None else solved:.1f} s"
    earlier = f" (solved earlier in {solved:.1f} s)" if solved is not None else ""
    return f"{job.description}{fewer} read from the cache in {job.seconds:.1f} s{earlier}"


def fewer_modes_text(job: SpectrumJob, spec: Spectrum) -> str:
    """``" (only 126: all the mesh has)"`` where the spectrum has fewer modes than asked
    for, else ``""``."""
    if spec.k >= job.spectrum_key.k:
        return ""
    unknowns = operator_info(spec.operator).unknowns(spec.n_vertices)
    why = ": all the mesh has" if spec.k >= unknowns else ""
    return f" (only {spec.k}{why})"


def ended_text(job: Job) -> str:
    """How ``job`` ended, in a line: done with its time, cancelled (or why) or failed."""
    if job.status == DONE:
        if isinstance(job, SpectrumJob) and job.result:
            return finished_text(job, job.result[0])
        return f"{job.description} in {job.seconds:.1f} s"
    if job.status == CANCELLED:
        return f"{job.description}: {job.error or 'cancelled'}"
    return f"{job.description}: failed"


def memory_text(spec: Spectrum) -> str:
    """``"; ... (memory limit)"`` naming a factor out of core (why it took longer) and a
    single-precision basis (why residuals are about 1e-7), else ``""``."""
    said = [
        words
        for words, key in ((OUT_OF_CORE_WORDS, "factor_out_of_core"),
                           (FLOAT32_BASIS_WORDS, "basis_float32"))
        if spec.parameters.get(key)
    ]  # fmt: skip
    return f"; {' and '.join(said)} (memory limit)" if said else ""


def residual_text(spec: Spectrum) -> str:
    """'largest relative residual 1.3e-05' and, where it is high, the mode's rounding
    floor: the residual rounding the mode to double precision alone causes (an
    estimate: no solver goes much below it)."""
    worst = float(np.max(spec.residuals[~spec.zero_mode_mask()], initial=0.0))
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
