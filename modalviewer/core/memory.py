"""How much memory a computation may use, and how much this process holds now.

The exact solver keeps its working set within :func:`memory_limit_mb`: where the
factorisation would not fit beside the Krylov basis, the factor goes out of core
(:mod:`.factor`).  The limit is half this machine's memory, so a computation leaves room
for the viewer, the rest of the desktop and the system's file cache (which then holds the
out-of-core factor); ``MODALVIEWER_MEMORY_LIMIT_MB`` sets it explicitly.
"""

from __future__ import annotations

import functools
import os

__all__ = [
    "MEMORY_LIMIT_SHARE",
    "memory_limit_mb",
    "physical_memory_mb",
    "glibc",
    "resident_mb",
    "return_freed_memory",
]

MEMORY_LIMIT_SHARE = 0.5
"""The share of this machine's memory a computation plans to stay within."""

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


def return_freed_memory() -> bool:
    """Give the memory this process has freed back to the system (glibc's
    ``malloc_trim(0)``: free heap pages, at its top and between the arrays still in use).
    A computation's stages free arrays of hundreds of megabytes whose heap pages glibc
    would otherwise keep (it serves arrays below its dynamic mmap threshold, up to 32 MB,
    and all arrays in a compute process, from the heap) and which the next stage's
    arrays, of other sizes, cannot always reuse; called at each new stage of
    :func:`.pipeline.compute_spectrum`.  True where it ran (glibc), False elsewhere."""
    import ctypes

    libc = glibc()
    trim = getattr(libc, "malloc_trim", None)
    if trim is None:
        return False
    trim.argtypes = [ctypes.c_size_t]
    trim.restype = ctypes.c_int
    trim(0)
    return True


@functools.cache
def glibc():
    """The C library as a ``ctypes.CDLL`` on Linux (glibc's ``libc.so.6``), else None,
    loaded once: the one place its allocator settings (:func:`return_freed_memory`, at
    each stage of a computation; :mod:`modalviewer.processes.memory`) load it from."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL("libc.so.6", use_errno=True)
    except OSError:
        return None
