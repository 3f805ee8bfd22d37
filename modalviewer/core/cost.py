"""The memory of an exact spectrum computation: the solver's plan (the Krylov basis's
size, the factor's budget, a single-precision basis) and the predictions from the mesh's
size alone (the memory check that refuses what would not fit)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .memory import resident_mb

MB = 2**20

GROWTH_MODES = 100  # the number of modes the growth laws' runs computed

# The Krylov basis holds (1 + BASIS_EXTRA) times the working pairs: more converges in
# fewer operator applications but costs memory and orthogonalisation time.  Where the
# vectors beyond the working pairs would take more than BASIS_EXTRA_BYTES, at most
# BASIS_EXTRA_MAX of them: there the basis is the largest array beside the factor and
# they buy little speed ("Iteration" in docs/how-it-works.md).  At least
# MIN_WORKING_PAIRS pairs: with fewer, clustered spectra (a mesh of many similar parts)
# did not converge.
BASIS_EXTRA = 0.6
BASIS_EXTRA_MAX = 112
BASIS_EXTRA_BYTES = 900e6
MIN_WORKING_PAIRS = 24


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
    """The memory (MB) a factor may take so that the solve stays within ``limit_mb``
    (None: no limit): what is left after this process's resident memory, the Krylov
    basis and the iteration's :data:`TEMPORARY_BLOCKS` (N, block) temporaries."""
    if limit_mb is None:
        return None
    arrays = 8.0 * n * (basis_columns + TEMPORARY_BLOCKS * block) / 2**20
    return limit_mb - resident_mb() - arrays


# (N, block) arrays alive beside the basis: the operator's scaled right-hand sides,
# PARDISO's solution, the orthogonalisation's copy and its Cholesky-QR products; the
# refinement's four (N, 2 block) ones
TEMPORARY_BLOCKS = 8


def float32_basis_mb(n: int, basis_columns: int, out_columns: int) -> float:
    """Memory (MB) of the buffer that holds a single-precision Krylov basis and, after
    it, the ``out_columns`` double-precision modes (:func:`.eigen._widen_in_place`)."""
    return max(8.0 * n * out_columns, 4.0 * n * basis_columns) / 2**20


def basis_in_float32(
    limit_mb: float | None, n: int, basis_columns: int, out_columns: int, block: int
) -> bool:
    """Whether the Krylov basis is kept in single precision: only where the
    double-precision one does not fit in ``limit_mb`` beside the factor and the
    single-precision buffer is smaller (it limits the tolerance to
    :data:`.eigen.FLOAT32_BASIS_TOL`)."""
    left_mb = factor_budget_mb(limit_mb, n, basis_columns, block)  # now: after the factor
    if left_mb is None or left_mb >= 0:
        return False
    return float32_basis_mb(n, basis_columns, out_columns) < 8.0 * n * basis_columns / 2**20


def basis_columns(k: int, n_unknowns: int) -> int:
    """Columns of the exact solver's Krylov basis array for ``k`` modes of ``n_unknowns``."""
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
    and of the modes in full, more than the peak holds at once, so the prediction errs
    on the side of refusing ("Memory check" in docs/performance.md)."""
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
    size, measured on the reference machine (``benchmarks/results/growth.json``)."""

    peak_mb_at_100k: float
    memory_exponent: float

    def peak_mb(self, n_vertices: int) -> float:
        return power_of_size(self.peak_mb_at_100k, self.memory_exponent, n_vertices)


@dataclass(frozen=True)
class FactorLaw:
    """Memory (MB) of the exact solver's factorisation as powers of the mesh size, in core
    and out of core (PARDISO's symbolic data and working buffer, the factor in a file)
    (``benchmarks/results/factor_memory.json``)."""

    in_core_mb_at_100k: float
    in_core_exponent: float
    out_of_core_mb_at_100k: float
    out_of_core_exponent: float

    def in_core_mb(self, n_vertices: int) -> float:
        return power_of_size(self.in_core_mb_at_100k, self.in_core_exponent, n_vertices)

    def out_of_core_mb(self, n_vertices: int) -> float:
        return power_of_size(self.out_of_core_mb_at_100k, self.out_of_core_exponent, n_vertices)


FILL_MARGIN = 1.26
"""The memory check counts a factor in core at this times its law: the largest ratio of
the curved meshes PARDISO analysed (closed curved surfaces fill in more than the plates
the laws come from; ``factor_memory.json``'s curved rows, checked by
tests/core/test_cost.py)."""


def factor_goes_out_of_core(
    in_core_peak_mb: float, factor: FactorLaw | None, n_vertices: int, limit_mb: float | None
) -> bool:
    """Whether the exact solver will keep its factor in a file: the in-core peak above
    ``limit_mb``, out of core needing less, and PARDISO (the only backend with that mode)
    there."""
    if factor is None or limit_mb is None or in_core_peak_mb <= limit_mb:
        return False
    if factor.out_of_core_mb(n_vertices) >= factor.in_core_mb(n_vertices):
        return False
    from .factor import available_backends  # imported late: cost is imported by everything

    return "pardiso" in available_backends()
