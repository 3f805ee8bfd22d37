"""OpenBLAS at one thread during an eigensolve, set at run time.

MKL PARDISO and numpy's OpenBLAS take turns on the same cores hundreds of times per
eigensolve, and OpenBLAS threads left spinning after each call slow PARDISO's down.
``OPENBLAS_THREAD_TIMEOUT`` (set by ``import modalviewer``) is read only when OpenBLAS
loads, too late if numpy was imported first; :func:`single_blas_thread` works whatever
the import order, limiting OpenBLAS to one thread through threadpoolctl for the
decorated call (``benchmarks/import_order.py`` measures it).  Without threadpoolctl or
OpenBLAS the call runs as it is; ``MODALVIEWER_SINGLE_BLAS_THREAD=0`` turns it off.
"""

from __future__ import annotations

import functools
import os

_OPENBLAS = None  # threadpoolctl's controller of the loaded OpenBLAS libraries, or False


def _openblas():
    global _OPENBLAS
    if _OPENBLAS is None:
        try:
            from threadpoolctl import ThreadpoolController

            found = ThreadpoolController().select(internal_api="openblas")
            _OPENBLAS = found if found.lib_controllers else False
        except Exception:  # threadpoolctl missing or failing on this platform
            _OPENBLAS = False
    return _OPENBLAS


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
