"""Memory settings for a computation process.

A spectrum computation allocates and frees many arrays of hundreds of megabytes (an
(N, 100) block of doubles), and first touches of fresh memory cost more than much of the
arithmetic done with it.  Two
settings make them cheaper:

- glibc hands every array above its mmap threshold to the kernel and back
  (``mmap``/``munmap``), so each new one starts on fresh pages.  Serving arrays up to
  32 MiB (glibc's largest threshold: vectors, the solver's work arrays, blocks of a few
  columns) from the heap and not trimming it lets a process reuse what it freed
  (:func:`keep_freed_memory`), whose pages are already mapped.  Bigger arrays (the
  (N, k) blocks and bases) still go back as they are freed: served from the heap too,
  they leave holes the next ones do not fit, which raises the peak.
- numpy advises the kernel to back big arrays with transparent huge pages, and the
  kernel compacts memory to find them, which makes the page faults of fresh arrays
  several times slower (:func:`no_huge_page_advice`).

Keeping freed memory has a cost where threads allocate: glibc gives each thread that
calls ``malloc`` an arena of its own, and what one arena keeps no other can reuse, so
arrays freed on the solver's and the row passes' threads stay resident beside new ones
made on the main thread.  One arena for the whole process (:func:`one_malloc_arena`)
lets every thread reuse them.

What each setting saves and costs: "Memory" in docs/how-it-works.md.

:func:`prepare_compute_process` applies all three.  Only for processes that exist to compute
(the viewer's child processes, the command line, the benchmarks): memory goes back to
the system when the process ends, not before.
"""

from __future__ import annotations

import ctypes

__all__ = [
    "keep_freed_memory",
    "no_huge_page_advice",
    "one_malloc_arena",
    "prepare_compute_process",
]

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8

HEAP_ARRAY_MAX_BYTES = 32 * 2**20
"""Arrays up to this size come from the heap in a compute process and their memory is
reused when freed; bigger ones are mapped and unmapped (glibc's mmap threshold, at its
largest on 64-bit systems): serving every array from the heap raised the exact solves'
peak memory."""


def _mallopt():
    """glibc's ``mallopt`` with its argument types set, or None where the C library is
    not glibc."""
    from ..core.memory import glibc

    mallopt = getattr(glibc(), "mallopt", None)
    if mallopt is not None:
        mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
        mallopt.restype = ctypes.c_int
    return mallopt


def keep_freed_memory() -> bool:
    """Ask glibc to serve allocations up to :data:`HEAP_ARRAY_MAX_BYTES` from the heap
    and keep freed heap memory (``mallopt(M_MMAP_THRESHOLD, 32 MiB)``,
    ``mallopt(M_TRIM_THRESHOLD, 2 GiB)``).  True if both took effect; False (and nothing
    changed) where the C library is not glibc."""
    mallopt = _mallopt()
    if mallopt is None:
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, HEAP_ARRAY_MAX_BYTES)) and bool(
        mallopt(_M_TRIM_THRESHOLD, 2**31 - 1)
    )


def one_malloc_arena() -> bool:
    """Ask glibc to serve every thread from one arena (``mallopt(M_ARENA_MAX, 1)``), so
    memory freed on one thread is reused by the next allocation on any other.  Takes
    effect for threads that have not yet allocated: call it when the process starts.
    True if it took effect; False where the C library is not glibc."""
    mallopt = _mallopt()
    return mallopt is not None and bool(mallopt(_M_ARENA_MAX, 1))


def no_huge_page_advice() -> bool:
    """Stop numpy from advising huge pages for new arrays (what the environment variable
    ``NUMPY_MADVISE_HUGEPAGE=0`` does at import).  True if the setting exists."""
    import numpy as np

    core = getattr(np, "_core", None) or np.core
    setter = getattr(core.multiarray, "_set_madvise_hugepage", None)
    if setter is None:
        return False
    setter(False)
    return True


def prepare_compute_process() -> bool:
    """The three settings of this module; True if all took effect."""
    kept = keep_freed_memory()
    shared = one_malloc_arena()
    return no_huge_page_advice() and kept and shared
