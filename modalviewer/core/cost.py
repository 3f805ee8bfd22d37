"""Time and memory predictions of a spectrum computation, from its size alone."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "FILL_MARGIN",
    "FactorLaw",
    "GrowthLaw",
    "OUT_OF_CORE_TIME_FACTOR",
    "basis_columns",
    "exact_peak_mb",
    "factor_goes_out_of_core",
    "float32_basis_saving_mb",
    "power_of_size",
]

MB = 2**20

GROWTH_MODES = 100
"""The number of modes the growth laws' runs computed."""


def basis_columns(k: int, n_unknowns: int) -> int:
    """Columns of the exact solver's Krylov basis array for ``k`` modes of ``n_unknowns``
    (:func:`.eigen.krylov_sizes`): with the modes, the arrays whose size grows with k."""
    from .eigen import krylov_sizes  # the solver's own rule; imported late (no cycle)

    n = max(int(n_unknowns), 2)
    k = max(1, min(int(k), n))
    _, block, max_basis, _ = krylov_sizes(k, n)
    return max_basis + block


def float32_basis_saving_mb(n_unknowns: int, k: int) -> float:
    """Memory (MB) the exact solver saves with a single-precision Krylov basis
    (:func:`.eigen.basis_in_float32`) against :func:`exact_peak_mb`: its
    double-precision basis array and the mode columns counted beside it above
    :data:`GROWTH_MODES`, less the one buffer that holds the single-precision basis and
    then the modes.  The 3D shells' 300 modes of the 1M-vertex plate, factor out of core:
    14 289 MB measured, 1.00 times this prediction (``benchmarks/results/memory.json``)."""
    from .eigen import float32_basis_mb  # the solver's own rule; imported late (no cycle)

    n = max(int(n_unknowns), 2)
    k = max(1, min(int(k), n))
    columns = basis_columns(k, n)
    beside = 8.0 * n * (columns + max(0, k - min(GROWTH_MODES, n))) / MB
    return max(0.0, beside - float32_basis_mb(n, columns, k))


def exact_peak_mb(law: GrowthLaw, n_vertices: int, n_unknowns: int, k: int) -> float:
    """Peak memory (MB) of an exact solve of ``k`` modes: the measured law at
    :data:`GROWTH_MODES` modes plus, for each further mode, its share of the arrays that
    grow with k: the Krylov basis (:func:`basis_columns`) and the modes themselves, one
    column of ``n_unknowns`` doubles each (fewer modes: less of them).  The memory check
    adds the factor's further fill on curved meshes (:data:`FILL_MARGIN`,
    :meth:`.operators.OperatorInfo.predicted_peak_mb`); with it, runs it was not fitted
    to measured 0.82 to 1.02 times the prediction from 100k vertices: 300 modes on the
    337k plate for all four operators 0.82 to 0.83 (every further column is counted in
    full; the solve's peak holds fewer at once), 100 modes on Loop-subdivided spot, the
    hand, the cow and Cheburashka (curved, thin parts, 107k to 206k vertices) 0.92 to
    1.02, the 3D shells' 300 modes of Cheburashka at 427k vertices 0.99
    (``benchmarks/growth.py``, "Memory check" in docs/performance.md)."""
    n = max(int(n_unknowns), 1)
    k, k0 = min(int(k), n), min(GROWTH_MODES, n)
    columns = basis_columns(k, n) - basis_columns(k0, n) + (k - k0)
    arrays = 8.0 * n * (basis_columns(k, n) + k) / MB  # there whatever the law says
    return max(law.peak_mb(n_vertices) + 8.0 * n * columns / MB, arrays)


def power_of_size(at_100k: float, exponent: float, n_vertices: int) -> float:
    """``at_100k * (n_vertices / 100k) ** exponent``: the form of every fitted law here."""
    return at_100k * (max(int(n_vertices), 1) / 1e5) ** exponent


LAWS_FROM_VERTICES = 100_000
"""The growth laws are fitted to the runs from this many vertices on
(``benchmarks.growth``); below it fixed costs dominate and the laws do not hold (the 3D
shells' fast preview: 0.30 of the exact time at 10k and 0.13 at 33k vertices, where its
law would say 0.09)."""


@dataclass(frozen=True)
class GrowthLaw:
    """Seconds and peak memory of one computation as powers of the mesh size and of the
    number of modes, measured on the reference machine (``benchmarks/growth.py``: bumpy
    plates of 100k to 1M vertices with 100 modes, each run in its own process, and the
    337k plate with 300 modes for ``mode_exponent``; ``benchmarks/results/growth.json``
    and ``growth_k300.json`` hold the runs)."""

    seconds_at_100k: float
    time_exponent: float
    peak_mb_at_100k: float
    memory_exponent: float
    mode_exponent: float = 1.0

    def seconds(self, n_vertices: int, k: int) -> float:
        """Predicted seconds for ``k`` modes: the fit at 100 modes times
        ``(k / 100) ** mode_exponent``."""
        at_100 = power_of_size(self.seconds_at_100k, self.time_exponent, n_vertices)
        return at_100 * (k / 100) ** self.mode_exponent

    def peak_mb(self, n_vertices: int) -> float:
        """Predicted peak resident memory (MB) of the computing process, at
        :data:`GROWTH_MODES` modes."""
        return power_of_size(self.peak_mb_at_100k, self.memory_exponent, n_vertices)


@dataclass(frozen=True)
class FactorLaw:
    """Memory (MB) of the exact solver's factorisation as powers of the mesh size: kept
    in core, and out of core (PARDISO's symbolic data and working buffer, the factor in
    a file), from PARDISO's analysis of the bumpy plates of 100k to 1M vertices
    (``benchmarks/factor_memory.py``, ``benchmarks/results/factor_memory.json``)."""

    in_core_mb_at_100k: float
    in_core_exponent: float
    out_of_core_mb_at_100k: float
    out_of_core_exponent: float

    def in_core_mb(self, n_vertices: int) -> float:
        return power_of_size(self.in_core_mb_at_100k, self.in_core_exponent, n_vertices)

    def out_of_core_mb(self, n_vertices: int) -> float:
        return power_of_size(self.out_of_core_mb_at_100k, self.out_of_core_exponent, n_vertices)


FILL_MARGIN = 1.26
"""The memory check counts an exact solve's factor at this times its law
(:class:`FactorLaw`): closed curved surfaces fill in more than the plates the laws come
from.  PARDISO's analysis of Loop-subdivided spot (187k vertices) and the hand (206k)
gives their 3D shells' factors 1.256 and 1.235 times the law in core, their scalar
operators' 1.15 to 1.23 times (``benchmarks/results/factor_memory.json``, "curved").
Without it the prediction for the 3D shells of such meshes would be up to 1.15 times
too low; with it the plates' own runs need 0.82 to 0.9 of the prediction, so there the
check errs on the side of refusing."""

OUT_OF_CORE_TIME_FACTOR = 1.2
"""An exact solve whose factor is out of core takes this times as long (its solves read
the factor back from the file): measured on cheburashka Loop-subdivided three times
(427k vertices, 3D shells, 300 modes, ``benchmarks/results/memory.json``)."""


def factor_goes_out_of_core(
    in_core_peak_mb: float, factor: FactorLaw | None, n_vertices: int, limit_mb: float | None
) -> bool:
    """Whether the exact solver will keep its factor in a file: where the in-core peak
    is above the memory limit (:func:`.memory.memory_limit_mb`), out of core needs less,
    and PARDISO (the only backend with an out-of-core mode) is there.  The solver
    decides on the factor's real size (:func:`.eigen.factor_budget_mb`); this is the
    same rule on the predicted sizes."""
    if factor is None or limit_mb is None or in_core_peak_mb <= limit_mb:
        return False
    if factor.out_of_core_mb(n_vertices) >= factor.in_core_mb(n_vertices):
        return False
    from .factor import available_backends  # imported late: cost is imported by everything

    return "pardiso" in available_backends()
