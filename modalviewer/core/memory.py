"""Keeping freed memory in a computation process.

A spectrum computation allocates and frees many arrays of hundreds of megabytes (130k
vertices, shells: each (N, 100) block is 313 MB).  glibc hands every such array to the
kernel and back (``mmap``/``munmap``), so each new one starts on fresh pages, and with
transparent huge pages the kernel compacts memory to back them: on the reference machine
the first touch of a fresh 313 MB array takes 0.7 s, of a reused one 0.06 s.  Serving
big arrays from the heap and not trimming it lets a process reuse what it freed.

Only for processes that exist to compute (the viewer's child processes, the command
line): memory goes back to the system when the process ends, not before.
"""

from __future__ import annotations

import ctypes
import sys

__all__ = ["keep_freed_memory"]

_M_TRIM_THRESHOLD = -1
_M_MMAP_MAX = -4


def keep_freed_memory() -> bool:
    """Ask glibc to serve big allocations from the heap and keep freed heap memory
    (``mallopt(M_MMAP_MAX, 0)``, ``mallopt(M_TRIM_THRESHOLD, 2 GiB)``).  True if both
    took effect; False (and nothing changed) where the C library is not glibc."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL("libc.so.6").mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, 2**31 - 1))
