"""The memory of an exact spectrum computation: the exact solver's plan (the Krylov
basis's size, the memory its factor may take, when the basis is kept in single
precision) and the predictions from the mesh's size alone (the memory check that
refuses what would not fit)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .memory import resident_mb

__all__ = [
    "FILL_MARGIN",
    "FactorLaw",
    "GrowthLaw",
    "basis_columns",
    "basis_in_float32",
    "factor_budget_mb",
    "float32_basis_mb",
    "krylov_sizes",
    "exact_peak_mb",
    "factor_goes_out_of_core",
    "float32_basis_saving_mb",
    "power_of_size",
]

MB = 2**20

GROWTH_MODES = 100
"""The number of modes the growth laws' runs computed."""

LAWS_FROM_VERTICES = 100_000
"""The growth laws are fitted to the runs from this many vertices on
(``benchmarks.growth``); below it fixed costs dominate."""


BASIS_EXTRA = 0.6
"""The Krylov basis holds (1 + BASIS_EXTRA) times the working number of pairs (fewer
extra vectors for big solves: :data:`BASIS_EXTRA_MAX`): more converges in fewer operator
applications but costs memory and orthogonalisation time (the basis sizes and the
choice: "Iteration" in docs/how-it-works.md)."""
BASIS_EXTRA_MAX = 112
BASIS_EXTRA_BYTES = 900e6
"""Where the basis's vectors beyond the working pairs would take more than
BASIS_EXTRA_BYTES, it holds at most BASIS_EXTRA_MAX of them: there the basis is the
largest array beside the factor, and the extra vectors buy little speed.  Smaller bases
are left alone: there fewer extra vectors cost more time than the memory they save
("Iteration" in docs/how-it-works.md)."""
MIN_WORKING_PAIRS = 24
"""The iteration works with at least this many pairs (where the space allows): with a
basis of 20 columns for a few wanted pairs, clustered spectra (a mesh of many similar
parts) did not converge in 60 restarts."""


def krylov_sizes(k: int, n_free: int, block: int | None = None) -> tuple[int, int, int, int]:
    """(working pairs, block size, basis size, pairs kept at a restart) for k pairs in a
    space of dimension ``n_free``; the basis array has ``basis size + block`` columns."""
    k_work = max(k, min(n_free // 2, max(k + max(8, k // 10), MIN_WORKING_PAIRS)))
    if block is None:
        block = int(np.clip(k_work // 16, 4, 16))
    extra = int(BASIS_EXTRA * k_work)
    if 8.0 * n_free * extra > BASIS_EXTRA_BYTES:
        extra = min(extra, BASIS_EXTRA_MAX)
    max_basis = k_work + max(2 * block, extra)
    max_basis = ((max_basis + block - 1) // block) * block
    return k_work, block, max_basis, k_work + (max_basis - k_work) // 3


def factor_budget_mb(limit_mb: float | None, n: int, basis_columns: int, block: int):
    """The memory (MB) a factor may take so that the solve stays within ``limit_mb``:
    what is left after this process's resident memory, the Krylov basis array and the
    iteration's (N, block) temporaries (at most :data:`TEMPORARY_BLOCKS` of them,
    the refinement's double blocks included); None if there is no limit."""
    if limit_mb is None:
        return None
    arrays = 8.0 * n * (basis_columns + TEMPORARY_BLOCKS * block) / 2**20
    return limit_mb - resident_mb() - arrays


TEMPORARY_BLOCKS = 8
"""(N, block) arrays alive beside the basis during the iteration: the operator's
scaled right-hand sides, PARDISO's solution, the orthogonalisation's copy and its
Cholesky-QR products; the refinement's four (N, 2 block) ones."""


def float32_basis_mb(n: int, basis_columns: int, out_columns: int) -> float:
    """Memory (MB) of the buffer that holds a single-precision Krylov basis of
    ``basis_columns`` columns and, after it, the ``out_columns`` double-precision
    modes in the same memory (:func:`.eigen._widen_in_place`)."""
    return max(8.0 * n * out_columns, 4.0 * n * basis_columns) / 2**20


def basis_in_float32(
    limit_mb: float | None, n: int, basis_columns: int, out_columns: int, block: int
) -> bool:
    """Whether the Krylov basis is stored in single precision: where resident memory (the
    factor included) and a double-precision basis with the iteration's temporaries
    exceed ``limit_mb`` and the single-precision buffer (:func:`float32_basis_mb`) is
    smaller.  Double precision is kept wherever it fits: single precision limits the
    tolerance to :data:`.eigen.FLOAT32_BASIS_TOL`."""
    left_mb = factor_budget_mb(limit_mb, n, basis_columns, block)  # now: after the factor
    if left_mb is None or left_mb >= 0:
        return False
    return float32_basis_mb(n, basis_columns, out_columns) < 8.0 * n * basis_columns / 2**20


def basis_columns(k: int, n_unknowns: int) -> int:
    """Columns of the exact solver's Krylov basis array for ``k`` modes of ``n_unknowns``
    (:func:`krylov_sizes`): with the modes, the arrays whose size grows with k."""
    n = max(int(n_unknowns), 2)
    k = max(1, min(int(k), n))
    _, block, max_basis, _ = krylov_sizes(k, n)
    return max_basis + block


def float32_basis_saving_mb(n_unknowns: int, k: int) -> float:
    """Memory (MB) a single-precision Krylov basis saves against :func:`exact_peak_mb`:
    the double-precision basis and the mode columns counted beside it, less the one
    buffer that holds the single-precision basis and then the modes."""
    n = max(int(n_unknowns), 2)
    k = max(1, min(int(k), n))
    columns = basis_columns(k, n)
    beside = 8.0 * n * (columns + max(0, k - min(GROWTH_MODES, n))) / MB
    return max(0.0, beside - float32_basis_mb(n, columns, k))


def exact_peak_mb(law: GrowthLaw, n_vertices: int, n_unknowns: int, k: int) -> float:
    """Peak memory (MB) of an exact solve of ``k`` modes: the measured law at
    :data:`GROWTH_MODES` modes plus, per further mode, its columns of the Krylov basis
    (:func:`basis_columns`) and of the modes, ``n_unknowns`` doubles each.  Every further
    column is counted in full, more than the peak holds at once, so the prediction errs
    on the side of refusing ("Memory check" in docs/performance.md); the factor's fill on
    curved meshes is added by :meth:`.operators.OperatorInfo.predicted_peak_mb`."""
    n = max(int(n_unknowns), 1)
    k, k0 = min(int(k), n), min(GROWTH_MODES, n)
    columns = basis_columns(k, n) - basis_columns(k0, n) + (k - k0)
    arrays = 8.0 * n * (basis_columns(k, n) + k) / MB  # there whatever the law says
    return max(law.peak_mb(n_vertices) + 8.0 * n * columns / MB, arrays)


def power_of_size(at_100k: float, exponent: float, n_vertices: int) -> float:
    """``at_100k * (n_vertices / 100k) ** exponent``: the form of every fitted law here."""
    return at_100k * (max(int(n_vertices), 1) / 1e5) ** exponent


@dataclass(frozen=True)
class GrowthLaw:
    """Peak memory of an exact solve of :data:`GROWTH_MODES` modes as a power of the mesh
    size, measured on the reference machine (``benchmarks/growth.py``: bumpy plates of
    100k to 1M vertices, each run in its own process; ``benchmarks/results/growth.json``
    holds the runs)."""

    peak_mb_at_100k: float
    memory_exponent: float

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
"""The memory check counts an exact solve's factor in core at this times its law
(:class:`FactorLaw`): closed curved surfaces fill in more than the plates the laws come
from.  It is the largest in-core factor of the curved meshes PARDISO analysed over the
plates' law (``benchmarks/results/factor_memory.json``, "curved"; tests/core/test_cost.py
checks it), so on the plates themselves the check errs on the side of refusing."""


def factor_goes_out_of_core(
    in_core_peak_mb: float, factor: FactorLaw | None, n_vertices: int, limit_mb: float | None
) -> bool:
    """Whether the exact solver will keep its factor in a file: the in-core peak above
    the memory limit (:func:`.memory.memory_limit_mb`), out of core needing less, and
    PARDISO (the only backend with that mode) there.  The rule of
    :func:`factor_budget_mb`, on the predicted sizes."""
    if factor is None or limit_mb is None or in_core_peak_mb <= limit_mb:
        return False
    if factor.out_of_core_mb(n_vertices) >= factor.in_core_mb(n_vertices):
        return False
    from .factor import available_backends  # imported late: cost is imported by everything

    return "pardiso" in available_backends()
