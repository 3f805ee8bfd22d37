"""``compute_spectrum``: operator assembly plus eigensolver, with progress and cancel;
:func:`exact_pairs` finds the pairs, ``compute_spectrum`` checks their residuals and
wraps them in a :class:`.spectrum.Spectrum`."""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .assembly import operator_matrices
from .eigen import (
    CancelFn,
    EigenError,
    EigenResult,
    ProgressFn,
    progress_reporter,
    rounding_floors,
    solve_lowest,
    typical_eigenvalue,
    zero_modes,
)
from .memory import return_freed_memory
from .mesh import Mesh
from .nullspace import NullSpace, null_space
from .operators import DEFAULT_K, OperatorInfo, OperatorLike, operator_info
from .spectrum import GrowingSpectrum, Spectrum, in_input_numbering
from .validate import check_count

FLOOR_FACTOR = 10.0
"""Residuals above RESIDUAL_LIMIT are accepted up to this times their rounding floor:
LAPACK's dense eigenvectors and the Krylov solver's land within a few times it."""


class ZeroModesWarning(UserWarning):
    """Every requested mode is a zero mode (exact ones: constants or rigid motions of the
    mesh's components; or eigenvalues at rounding level, :func:`.eigen.zero_modes`):
    nothing of the shape's vibrations is in the spectrum.  Raised by a mesh of many
    separate (or only vertex-joined) pieces, a damaged file, or k not larger than the
    null space's dimension."""


WELL_SHAPED_RESIDUAL = 1e-8
"""The relative residual the tests require on well-shaped meshes; above it, the worst
mode's rounding floor is kept in ``parameters["worst_residual_rounding_floor"]`` to
report the residual beside what double precision allows."""

RESIDUAL_LIMIT = 1e-4
"""A spectrum whose non-zero modes have a larger relative residual is rejected, unless
the residual is within ``FLOOR_FACTOR`` of the mode's rounding floor
(:func:`.eigen.rounding_floors`, below which no solver goes).  Sliver triangles make the
operator so ill-conditioned that the floor rises far above the residuals of well-shaped
meshes; such spectra are accepted and carry their residuals (the viewer shows the
largest)."""


def sliver_hint(mesh: Mesh, threshold: float = 1e-3) -> str:
    """What the mesh's nearly degenerate triangles (quality 4 sqrt(3) area / sum of
    squared edge lengths below ``threshold``; 1 is equilateral) may have to do with a
    failed solve, or "" if there are none (no advice that may be wrong for the case: the
    exactly known null vectors are already deflated)."""
    quality = mesh.face_quality
    bad = np.flatnonzero(quality < threshold)
    if bad.size == 0:
        return ""
    worst = int(bad[np.argmin(quality[bad])])
    return (
        f"; the mesh has {bad.size} nearly degenerate triangles (quality below "
        f"{threshold:g}; the worst, face {worst}, {quality[worst]:.1e}), which make the "
        "operator ill-conditioned: remesh it (or clean those triangles) and try again"
    )


PREVIEW_REMOVED = (
    "the preview spectrum was removed: every spectrum is exact. For modes to look at "
    "early, pass on_modes= (a callback that receives the lowest exact modes as they "
    "converge) or ask for fewer modes k"
)
"""Why ``accuracy="preview"`` fails, and what to use instead (the library's ValueError;
the command line's ``--preview`` says the same)."""


def compute_spectrum(
    mesh: Mesh,
    operator: OperatorLike,
    k: int = DEFAULT_K,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    accuracy: str = "exact",
    on_modes: Callable[[Spectrum], None] | None = None,
) -> Spectrum:
    """The k lowest eigenpairs of ``operator`` (a name of :data:`.operators.OPERATOR_INFO`
    or its :class:`.operators.OperatorInfo`) on ``mesh``: a Spectrum with ascending
    eigenvalues and Mass-orthonormal modes, (n, k) or (n, 3, k), one row per vertex of
    ``mesh`` (NaN for ``mesh.unused``, a merged duplicate's row that of its vertex).  The
    operator's exact null vectors (:mod:`.nullspace`) come first as eigenvalue 0, counted
    in k (``spec.null_space_dimension``).

    k is an integer >= 1 (:mod:`.validate`), capped at the number of unknowns; bending
    and membrane weigh the Discrete Shells energy (the scalar energies ignore them).
    ``progress(stage, fraction)`` has fraction in [0, 1]; ``cancel`` is polled, and
    returning True raises :class:`Cancelled`.  ``accuracy`` is "exact", the only value;
    the removed "preview" and "fast preview" raise a ValueError saying what to use
    instead (:data:`PREVIEW_REMOVED`).  ``on_modes(spectrum_so_far)`` is called in the
    computing thread whenever more modes have converged, with a Spectrum of the first j
    (as :func:`.eigen.solve_lowest` hands them over), ``is_complete`` False, residuals
    NaN; the last call has the finished spectrum (the only one for small problems).
    """
    operator = operator_info(operator)  # a ValueError naming the known operators
    k = check_count(k, "k")
    if accuracy in ("preview", "fast preview"):  # refused with advice
        raise ValueError(f"accuracy={accuracy!r}: {PREVIEW_REMOVED}")
    if accuracy != "exact":
        raise ValueError(f"accuracy must be 'exact', got {accuracy!r}")
    if mesh.solver_mesh is not mesh:  # unused or merged vertices: solve on the others
        relay = None if on_modes is None else lambda part: on_modes(in_input_numbering(part, mesh))
        solved = compute_spectrum(
            mesh.solver_mesh, operator, k, bending, membrane, progress, cancel, accuracy, relay
        )
        return in_input_numbering(solved, mesh)
    progress = _returning_freed_memory(progress)
    started = time.perf_counter()
    progress_reporter(progress, cancel)("assembling", 0.0)
    try:
        pairs = exact_pairs(mesh, operator, k, bending, membrane, progress, cancel, on_modes)
    except EigenError as exc:
        raise EigenError(f"{exc}{sliver_hint(mesh)}") from None
    result = pairs.result
    if not pairs.nonzero.any():
        warnings.warn(_all_zero_message(pairs), ZeroModesWarning, stacklevel=2)
    at_floor, worst_floor = _checked_residuals(pairs, mesh)
    progress("done", 1.0)
    parameters = {
        **pairs.parameters,
        "method": result.method,
        "shift": result.shift,
        "seconds_by_stage": {s: round(t, 4) for s, t in result.stage_seconds.items()},
        "operator_columns": result.operator_columns,
        "factor_mb": result.factor_mb,
        "factor_out_of_core": result.out_of_core,
        "basis_float32": result.basis_float32,
        "null_space_dimension": result.null_dim,
        "seconds_assembly": pairs.seconds_assembly,
        "seconds_total": time.perf_counter() - started,
        "modes_at_rounding_floor": at_floor,
        "worst_residual_rounding_floor": worst_floor,
    }
    per_vertex = operator.unknowns_per_vertex
    spectrum = Spectrum(
        eigenvalues=result.eigenvalues,
        modes=result.vectors.reshape(mesh.n_vertices, per_vertex, -1)
        if per_vertex > 1
        else result.vectors,
        operator=operator.name,
        mass=pairs.mass[::per_vertex],
        residuals=result.residuals,
        mesh_hash=mesh.hash,
        parameters=parameters,
    )
    if on_modes is not None:
        on_modes(spectrum)
    return spectrum


@dataclass(frozen=True)
class ExactPairs:
    """What :func:`exact_pairs` computed for ``K phi = lambda diag(mass) phi``."""

    K: sp.csr_matrix
    mass: np.ndarray
    nulls: NullSpace  # the operator's exact null vectors on the mesh (first in result)
    result: EigenResult  # the k lowest pairs (k capped at the number of unknowns)
    nonzero: np.ndarray  # (k,) bool, the pairs that are not zero modes
    seconds_assembly: float
    parameters: dict  # the spectrum's parameters every partial and whole one has


def exact_pairs(
    mesh: Mesh,
    operator: OperatorInfo,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    on_modes: Callable[[Spectrum], None] | None = None,
) -> ExactPairs:
    """The ``min(k, unknowns)`` lowest eigenpairs of ``operator`` on ``mesh``, the exact
    null vectors first; ``on_modes`` as :func:`compute_spectrum`'s, for ``mesh`` itself
    (no unused or merged vertices).  Raises what the assembly, the null space and
    :func:`.eigen.solve_lowest` raise (:class:`.mesh.MeshError`,
    :class:`.eigen.EigenError`, :class:`.eigen.Cancelled`)."""
    started = time.perf_counter()
    K, mass = operator_matrices(mesh, operator, bending, membrane)
    seconds_assembly = time.perf_counter() - started
    k = min(int(k), K.shape[0])
    nulls = null_space(mesh, operator, K, mass)
    scale = typical_eigenvalue(K, mass)
    parameters = {
        "k": k,
        "bending": float(bending),
        "membrane": float(membrane),
        "zero_mode_scale": scale,
        "n_components": nulls.n_components,
        "null_space": nulls.summary(),
    }
    relay = None
    if on_modes is not None:
        per_vertex = operator.unknowns_per_vertex
        modes = GrowingSpectrum(k)

        def relay(eigenvalues: np.ndarray, vectors: np.ndarray) -> None:
            """Collects the pairs solve_lowest hands over; a Spectrum of the first j."""
            if per_vertex > 1:  # rows 3i, 3i + 1, 3i + 2 are vertex i's
                vectors = vectors.reshape(mesh.n_vertices, per_vertex, -1)
            modes.append(eigenvalues, vectors)
            so_far = {
                **parameters,
                "method": "shift-invert block Krylov-Schur, converged Ritz pairs",
                "null_space_dimension": min(nulls.dimension, modes.count),
            }
            on_modes(modes.so_far(operator.name, mass[::per_vertex], mesh.hash, so_far))

    result = solve_lowest(
        K, mass, k, progress=progress, cancel=cancel, null_space=nulls.vectors, on_modes=relay
    )
    nonzero = ~zero_modes(result.eigenvalues, scale, result.null_dim)
    return ExactPairs(K, mass, nulls, result, nonzero, seconds_assembly, parameters)


def _checked_residuals(pairs, mesh: Mesh) -> tuple[int, float]:
    """(modes accepted at their rounding floor, the rounding floor of the worst mode
    above :data:`WELL_SHAPED_RESIDUAL`); an EigenError where a non-zero mode's residual
    is above :data:`RESIDUAL_LIMIT` and above ``FLOOR_FACTOR`` times its floor."""
    K, mass, result, nonzero = pairs.K, pairs.mass, pairs.result, pairs.nonzero
    residuals = result.residuals
    # modes above the accuracy well-shaped meshes reach: how close to rounding are they?
    loose = np.flatnonzero(nonzero & (residuals > min(WELL_SHAPED_RESIDUAL, RESIDUAL_LIMIT)))
    if loose.size == 0:
        return 0, 0.0
    floors_loose = rounding_floors(K, mass, result.eigenvalues[loose], result.vectors, loose)
    worst_floor = float(floors_loose[np.argmax(residuals[loose])])
    above = np.flatnonzero(nonzero & (residuals > RESIDUAL_LIMIT))
    floors = floors_loose[np.searchsorted(loose, above)]
    bad = above[residuals[above] > FLOOR_FACTOR * floors]
    if bad.size:
        raise EigenError(
            f"the eigensolver's residual {float(residuals[bad].max()):.1e} is above "
            f"{RESIDUAL_LIMIT:.0e} and above the rounding floor; the result is not "
            f"trustworthy{sliver_hint(mesh)}"
        )
    return int(above.size), worst_floor


def _returning_freed_memory(progress: ProgressFn | None) -> ProgressFn:
    """``progress`` that first gives freed memory back to the system at each new stage
    (:func:`.memory.return_freed_memory`), which lowers a solve's peak memory at no
    measurable cost in time."""
    stage_now = [None]

    def report(stage: str, fraction: float) -> None:
        if stage != stage_now[0]:
            stage_now[0] = stage
            return_freed_memory()
        if progress is not None:
            progress(stage, fraction)

    return report


def _all_zero_message(pairs: ExactPairs) -> str:
    """Why a spectrum holds only zero modes (see :class:`ZeroModesWarning`)."""
    result, nulls, lam_typical = pairs.result, pairs.nulls, pairs.parameters["zero_mode_scale"]
    k = result.eigenvalues.shape[0]
    if result.null_dim >= k:
        what = (
            "the only mode is an exact zero mode"
            if k == 1
            else f"all {k} modes are exact zero modes"
        )
        head = f"{what}: {nulls.summary()}"
    else:
        head = (
            f"all {k} eigenvalues are null-space values: {result.null_dim} exact zero "
            f"modes and {k - result.null_dim} more at rounding level (|lambda| at most "
            f"{float(np.abs(result.eigenvalues).max()):.1e}, against a typical eigenvalue "
            f"size of {lam_typical:.1e}): {nulls.summary()} Pieces that move freely "
            "(touching at single vertices, or a damaged file) add zero modes that are not "
            "known in advance."
        )
    if nulls.n_components > 1:
        advice = (
            f" Ask for more than {max(nulls.dimension, k)} modes, keep the largest "
            "component (modalviewer.largest_component) or compute per component "
            "(modalviewer.compute_spectrum_per_component)."
        )
    else:
        advice = (
            f" Ask for at least {max(nulls.dimension, k) + 1} modes to see the shape's vibrations."
        )
    return (
        head + " The mesh is made of separate pieces or is damaged, or k is not larger than "
        "the null space's dimension." + advice
    )
