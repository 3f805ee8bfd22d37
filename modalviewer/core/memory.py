"""Memory: how much a computation may use (:func:`memory_limit_mb`, leaving room for
the viewer, the desktop and the file cache that holds an out-of-core factor), how much
this process holds, the allocator settings for processes that compute, the exact
solver's plan (the Krylov basis's size, the factor's budget, a single-precision basis)
and the predictions from the mesh's size alone (the memory check that refuses what
would not fit)."""

from __future__ import annotations

import ctypes
import functools
import os
import sys
from bisect import bisect_right
from dataclasses import dataclass

import numpy as np

MEMORY_LIMIT_SHARE = 0.5  # the share of this machine's memory a computation plans for

MB = 2**20


def physical_memory_mb() -> float | None:
    """This machine's memory in MB, or None where the system does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / MB
    except (ValueError, OSError, AttributeError):
        return None


def memory_limit_mb() -> float | None:
    """``MODALVIEWER_MEMORY_LIMIT_MB`` if set (a positive number), else
    :data:`MEMORY_LIMIT_SHARE` of :func:`physical_memory_mb` (None if unknown)."""
    text = os.environ.get("MODALVIEWER_MEMORY_LIMIT_MB", "").strip()
    if text:
        try:
            value = float(text)
        except ValueError:
            raise ValueError(
                f"MODALVIEWER_MEMORY_LIMIT_MB must be a number of megabytes, got {text!r}"
            ) from None
        if value <= 0:
            raise ValueError(f"MODALVIEWER_MEMORY_LIMIT_MB must be positive, got {text!r}")
        return value
    physical = physical_memory_mb()
    return None if physical is None else MEMORY_LIMIT_SHARE * physical


def resident_mb() -> float:
    """Memory this process holds now (resident set, MB): ``/proc/self/statm`` on Linux,
    else the peak so far (``getrusage``), which is never less."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / MB
    except (OSError, ValueError, IndexError):
        import resource  # not on Windows, where /proc is not either

        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / 1024.0 if os.uname().sysname == "Linux" else peak / MB


@functools.cache
def glibc():
    """glibc's ``libc.so.6`` as a ``ctypes.CDLL`` on Linux, else None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL("libc.so.6", use_errno=True)
    except OSError:
        return None


def return_freed_memory() -> bool:
    """Give the memory this process has freed back to the system (glibc's
    ``malloc_trim(0)``; True where it ran): a stage's freed heap pages are not always
    reusable by the next stage's arrays of other sizes."""
    trim = getattr(glibc(), "malloc_trim", None)
    if trim is None:
        return False
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    trim(0)
    return True


# Arrays up to this size come from the heap in a compute process, their memory reused
# when freed; bigger ones are mapped (glibc's largest mmap threshold on 64-bit systems):
# serving every array from the heap leaves holes the next do not fit.
HEAP_ARRAY_MAX_BYTES = 32 * 2**20


def prepare_compute_process() -> bool:
    """The allocator settings for a process that exists to compute, called when it starts
    (True if all took effect).  A computation allocates and frees many large arrays, and
    first touches of fresh pages cost more than much of the arithmetic, so glibc serves
    arrays up to :data:`HEAP_ARRAY_MAX_BYTES` from the heap, keeps freed heap memory and
    serves every thread from one arena (memory freed on one thread is reused on any
    other); numpy stops advising huge pages (compaction slows page faults).  "Memory" in
    docs/how-it-works.md."""
    mallopt = getattr(glibc(), "mallopt", None)
    settings = [
        (-3, HEAP_ARRAY_MAX_BYTES),  # M_MMAP_THRESHOLD
        (-1, 2**31 - 1),  # M_TRIM_THRESHOLD: keep all freed memory
        (-8, 1),  # M_ARENA_MAX
    ]
    if mallopt is not None:
        mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
        mallopt.restype = ctypes.c_int
    took = [mallopt is not None and bool(mallopt(*setting)) for setting in settings]
    core = getattr(np, "_core", None) or np.core
    setter = getattr(core.multiarray, "_set_madvise_hugepage", None)
    if setter is not None:
        setter(False)
    return all(took) and setter is not None


MEMORY_SHARE = 0.75
"""Computations expected to need more than this share of the physical memory are refused
before they start."""


def largest_k_that_fits(operator, k: int, n_vertices: int, available: float) -> int:
    """The most modes, up to ``k``, whose predicted peak memory
    (:meth:`.operators.OperatorInfo.predicted_peak_mb`) stays within :data:`MEMORY_SHARE`
    of ``available`` bytes; 0 if not even one does."""
    ks, limit = range(1, max(1, k) + 1), MEMORY_SHARE * available  # memory grows with k
    return bisect_right(ks, limit, key=lambda j: operator.predicted_peak_mb(n_vertices, j) * MB)


def what_fits(
    operator, k: int, n_vertices: int, available: float, copy_vertices=None, coarse: str = ""
) -> str:
    """What would fit instead: fewer modes, ``k`` modes solved on a decimated copy of
    ``copy_vertices`` (named ``coarse``; only where the copy has ``k`` modes: as many
    modes as unknowns), or neither."""
    options = []
    fewer = largest_k_that_fits(operator, k, n_vertices, available)
    if fewer >= 1:
        options.append(f"at most {fewer} modes fit")
    if (
        copy_vertices is not None
        and k <= operator.unknowns(copy_vertices)
        and operator.predicted_peak_mb(copy_vertices, k) * MB <= MEMORY_SHARE * available
    ):
        options.append(f"{k} modes {coarse} fit")
    if not options:
        return "Not even one mode fits: use a coarser mesh or a machine with more memory."
    text = "; ".join(options)
    return text[0].upper() + text[1:] + "."


def memory_refusal(
    operator, k: int, n_vertices: int, copy_vertices=None, coarse: str = ""
) -> str | None:
    """A message if an exact solve of ``k`` modes of ``operator`` on ``n_vertices`` would
    need more than :data:`MEMORY_SHARE` of this machine's memory, saying what would fit
    (:func:`what_fits`); else None.  The viewer's refusals and ``modalviewer compute``
    say the same."""
    needed = operator.predicted_peak_mb(n_vertices, k) * MB  # bytes
    available = (physical_memory_mb() or 0.0) * MB  # bytes; 0 if unknown
    if not available or needed <= MEMORY_SHARE * available:
        return None
    share = {0.75: "three quarters", 0.5: "half"}.get(MEMORY_SHARE, f"{MEMORY_SHARE:.0%}")
    return (
        f"{operator.label} with {k} modes on {n_vertices} vertices "
        f"needs about {needed / 2**30:.1f} GiB of memory, more than the "
        f"{MEMORY_SHARE * available / 2**30:.1f} GiB a computation may take ({share} of this "
        f"machine's {available / 2**30:.1f} GiB). "
        + what_fits(operator, k, n_vertices, available, copy_vertices, coarse)
    )


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
