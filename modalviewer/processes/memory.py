"""Memory settings for a computation process.

A spectrum computation allocates and frees many arrays of hundreds of megabytes (130k
vertices, shells: each (N, 100) block is 313 MB), and on the reference machine first
touches of fresh memory cost more than much of the arithmetic done with it.  Two
settings make them cheaper:

- glibc hands every big array to the kernel and back (``mmap``/``munmap``), so each new
  one starts on fresh pages.  Serving big arrays from the heap and not trimming it lets
  a process reuse what it freed (:func:`keep_freed_memory`), whose pages are already
  mapped.
- numpy advises the kernel to back big arrays with transparent huge pages, and the
  kernel compacts memory to find them, which makes the page faults of fresh arrays
  several times slower (:func:`no_huge_page_advice`).

What each setting saves and costs: "Memory" in docs/how-it-works.md.

:func:`prepare_compute_process` applies both.  Only for processes that exist to compute
(the viewer's child processes, the command line, the benchmarks): memory goes back to
the system when the process ends, not before.
"""

from __future__ import annotations

import ctypes

__all__ = ["keep_freed_memory", "no_huge_page_advice", "prepare_compute_process"]

_M_TRIM_THRESHOLD = -1
_M_MMAP_MAX = -4


def keep_freed_memory() -> bool:
    """Ask glibc to serve big allocations from the heap and keep freed heap memory
    (``mallopt(M_MMAP_MAX, 0)``, ``mallopt(M_TRIM_THRESHOLD, 2 GiB)``).  True if both
    took effect; False (and nothing changed) where the C library is not glibc."""
    from ..core.memory import glibc

    mallopt = getattr(glibc(), "mallopt", None)
    if mallopt is None:
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, 2**31 - 1))


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
    """Both settings of this module; True if both took effect."""
    kept = keep_freed_memory()
    return no_huge_page_advice() and kept
