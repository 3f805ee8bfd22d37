"""Memory: how much a computation may use (:func:`memory_limit_mb`, leaving room for
the viewer, the desktop and the file cache that holds an out-of-core factor), how much
this process holds, and the allocator settings for processes that compute.

A computation allocates and frees many arrays of hundreds of megabytes, and first
touches of fresh pages cost more than much of the arithmetic:
:func:`prepare_compute_process` reuses heap memory, stops numpy's huge-page advice
(compaction slows page faults) and gives all threads one malloc arena ("Memory" in
docs/how-it-works.md).
"""

from __future__ import annotations

import ctypes
import functools
import os
import sys
from bisect import bisect_right

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
    (True if all took effect): glibc serves arrays up to :data:`HEAP_ARRAY_MAX_BYTES` from
    the heap, keeps freed heap memory and serves every thread from one arena (memory freed
    on one thread is reused on any other); numpy stops advising huge pages."""
    import numpy as np

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


def memory_needed(operator, k: int, n_vertices: int) -> float:
    """Bytes an exact solve of ``k`` modes of ``operator`` (an
    :class:`~.operators.OperatorInfo`) on ``n_vertices`` is predicted to need at its peak."""
    return operator.predicted_peak_mb(n_vertices, k) * MB


def largest_k_that_fits(operator, k: int, n_vertices: int, available: float) -> int:
    """The most modes, up to ``k``, whose expected memory stays within
    :data:`MEMORY_SHARE` of ``available`` bytes; 0 if not even one does."""
    ks, limit = range(1, max(1, k) + 1), MEMORY_SHARE * available  # memory grows with k
    return bisect_right(ks, limit, key=lambda j: memory_needed(operator, j, n_vertices))


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
        and memory_needed(operator, k, copy_vertices) <= MEMORY_SHARE * available
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
    needed = memory_needed(operator, k, n_vertices)
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
