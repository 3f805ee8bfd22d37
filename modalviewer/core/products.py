"""Sparse products on the machine's two cores, passes over (N, k) arrays in blocks, and
OpenBLAS at one thread during an eigensolve.

scipy's sparse products release the GIL but run on one core; splitting the rows of the
left factor over two threads halves their time on two cores.

:func:`single_blas_thread` sets OpenBLAS to one thread at run time through
threadpoolctl: OpenBLAS threads left spinning after each call slow MKL PARDISO's down,
and ``OPENBLAS_THREAD_TIMEOUT`` (set by ``import modalviewer``) comes too late if numpy
was imported first (``benchmarks/import_order.py``).
``MODALVIEWER_SINGLE_BLAS_THREAD=0`` turns it off.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.sparse as sp
from scipy.sparse import _sparsetools


def csr_rows(K: sp.csr_matrix, start: int, stop: int) -> sp.csr_matrix:
    """Rows ``start:stop`` of a CSR matrix sharing its arrays, set on an empty matrix:
    scipy's constructor copies any view smaller than half its base array."""
    p = K.indptr
    a, b = int(p[start]), int(p[stop])
    rows = sp.csr_matrix((stop - start, K.shape[1]), dtype=K.dtype)
    rows.indices = K.indices[a:b]
    rows.indptr = (p[start : stop + 1] - p[start]).astype(K.indices.dtype, copy=False)
    rows.data = K.data[a:b]
    rows.has_sorted_indices = K.has_sorted_indices  # K's, not the empty matrix's
    rows.has_canonical_format = K.has_canonical_format
    return rows


def row_halves(K: sp.csr_matrix) -> list[tuple[slice, sp.csr_matrix]]:
    """The two row halves of a CSR matrix as matrices sharing its arrays (no copy)."""
    N = K.shape[0]
    h = N // 2
    return [(slice(0, h), csr_rows(K, 0, h)), (slice(h, N), csr_rows(K, h, N))]


def threaded_product(K, X):
    """K @ X for a CSR matrix K and a dense array or sparse matrix X (a CSR result), the
    two row halves of K on two threads."""
    K = sp.csr_matrix(K)
    if sp.issparse(X):
        X = sp.csr_matrix(X)
        with ThreadPoolExecutor(2) as pool:
            parts = list(pool.map(lambda part: (part[1] @ X).tocsr(), row_halves(K)))
        return sp.vstack(parts, format="csr")
    X = np.ascontiguousarray(X)
    if X.ndim == 1 or X.shape[1] < 4 or K.shape[0] < 2:
        return np.asarray(K @ X)
    out = np.empty((K.shape[0],) + X.shape[1:])
    X2 = X.reshape(X.shape[0], -1)
    out2 = out.reshape(out.shape[0], -1)
    same_type = K.dtype == X2.dtype == np.float64

    def rows(part: tuple[slice, sp.csr_matrix]) -> None:
        s, M = part
        block = out2[s]
        if not same_type:
            block[...] = M @ X2
            return
        # scipy's kernel behind ``M @ X2`` (it adds M X2 to the block), which writes in
        # place instead of into a fresh array
        block.fill(0.0)
        _sparsetools.csr_matvecs(
            M.shape[0], M.shape[1], X2.shape[1], M.indptr, M.indices,
            M.data, X2.ravel(), block.ravel(),
        )  # fmt: skip

    with ThreadPoolExecutor(2) as pool:
        list(pool.map(rows, row_halves(K)))
    return out


def column_block_products(K, Y: np.ndarray, width: int = 32) -> Iterator[tuple[slice, np.ndarray]]:
    """``(cols, K @ Y[:, cols])`` for consecutive blocks of ``width`` columns of a sparse K:
    passes over ``K Y`` with (N, width) temporaries instead of an (N, k) one."""
    K = sp.csr_matrix(K)
    for start in range(0, Y.shape[1], width):
        cols = slice(start, start + width)
        yield cols, threaded_product(K, Y[:, cols])


def column_norms(A: sp.spmatrix) -> np.ndarray:
    """The Euclidean norm of each column of a sparse matrix."""
    return np.sqrt(np.asarray(A.multiply(A).sum(axis=0)).ravel())


def move_columns_in_place(Y: np.ndarray, m: int, chunk: int = 16384, lead: int = 0):
    """The first m columns of the C-contiguous (N, w) Y written over Y's buffer (Y is left
    meaningless) as columns ``lead:`` of an (N, lead + m) array, the first ``lead`` left
    for the caller; chunk by chunk, and row i ends at (i + 1)(lead + m) <= (i + 1) w, so
    writes never reach unread rows."""
    n, w = Y.shape
    width = lead + m
    if width > w or not Y.flags.c_contiguous:
        raise ValueError("Y must be C-contiguous with at least lead + m columns")
    out = Y.reshape(-1)[: n * width].reshape(n, width)
    for start in range(0, n, chunk):
        rows = slice(start, min(start + chunk, n))
        out[rows, lead:] = Y[rows, :m].copy()
    return out


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
