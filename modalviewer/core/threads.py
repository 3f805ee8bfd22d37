"""OpenBLAS at one thread during an eigensolve, set at run time through threadpoolctl:
OpenBLAS threads left spinning after each call slow MKL PARDISO's down, and
``OPENBLAS_THREAD_TIMEOUT`` (set by ``import modalviewer``) comes too late if numpy was
imported first (``benchmarks/import_order.py``).  ``MODALVIEWER_SINGLE_BLAS_THREAD=0``
turns it off.
"""

from __future__ import annotations

import functools
import os


@functools.cache
def _openblas():
    """threadpoolctl's controller of the loaded OpenBLAS libraries, or None."""
    try:
        from threadpoolctl import ThreadpoolController

        found = ThreadpoolController().select(internal_api="openblas")
        return found if found.lib_controllers else None
    except Exception:  # threadpoolctl missing or failing on this platform
        return None


def single_blas_thread(fn):
    """Decorator: ``fn`` runs with OpenBLAS at one thread."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        found = _openblas()
        if not found or os.environ.get("MODALVIEWER_SINGLE_BLAS_THREAD") == "0":
            return fn(*args, **kwargs)
        with found.limit(limits=1):
            return fn(*args, **kwargs)

    return wrapper
