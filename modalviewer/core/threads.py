"""OpenBLAS at one thread during an eigensolve, set at run time.

MKL PARDISO (Intel OpenMP threads) and the OpenBLAS of numpy and scipy take turns on
the same cores, hundreds of times per eigensolve.  OpenBLAS keeps its threads spinning
for a while after each call, and they slow PARDISO's threads down.  The idle timeout
(``OPENBLAS_THREAD_TIMEOUT``, set by ``import modalviewer``) is read only when OpenBLAS
loads, so it has no effect when numpy was imported first.  :func:`single_blas_thread`
works whatever the import order: through threadpoolctl, OpenBLAS runs on one thread for
the duration of the decorated call (the eigensolver), so no OpenBLAS thread spins beside
PARDISO.  PARDISO keeps all its threads, and Intel OpenMP's ``KMP_BLOCKTIME`` needs no
run-time setting: its library loads at the first PARDISO call, after
``import modalviewer``.  Measured by ``benchmarks/import_order.py``
(``benchmarks/results/import_order.json``).

Without threadpoolctl or without OpenBLAS (another BLAS) the call runs as it is;
``MODALVIEWER_SINGLE_BLAS_THREAD=0`` turns the limit off.
"""

from __future__ import annotations

import contextlib
import functools
import os

__all__ = ["blas_limit", "single_blas_thread"]

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


def blas_limit():
    """A context manager: OpenBLAS at one thread inside, as it was after it."""
    found = _openblas()
    if not found or os.environ.get("MODALVIEWER_SINGLE_BLAS_THREAD") == "0":
        return contextlib.nullcontext()
    return found.limit(limits=1)


def single_blas_thread(fn):
    """Decorator: ``fn`` runs inside :func:`blas_limit`."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with blas_limit():
            return fn(*args, **kwargs)

    return wrapper
