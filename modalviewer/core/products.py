"""Sparse products on the machine's two cores, and passes over (N, k) arrays in row blocks.

scipy's sparse products release the GIL but run on one core; splitting the rows of the
left factor over two threads halves their time on two cores.
"""

from __future__ import annotations

from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.sparse as sp
from scipy.sparse import _sparsetools

__all__ = [
    "ROW_BLOCK",
    "column_block_products",
    "row_blocks",
    "row_halves",
    "threaded_product",
    "threaded_transpose_product",
    "threaded_projection",
    "chunked_projection",
    "row_block_sums",
    "csr_rows",
    "transform_columns_in_place",
]


ROW_BLOCK = 3 * 2730
"""Rows per block in the passes over (N, k) arrays: a multiple of 3
(whole vertices of the shells' 3 x 3 blocks), an (8190, 100) block is 6.5 MB."""


def row_blocks(N: int):
    """Slices of ``ROW_BLOCK`` rows covering ``range(N)``: passes over (N, k) arrays in
    cache-sized blocks, without (N, k) temporaries."""
    return (slice(start, min(start + ROW_BLOCK, N)) for start in range(0, N, ROW_BLOCK))


def csr_rows(K: sp.csr_matrix, start: int, stop: int) -> sp.csr_matrix:
    """Rows ``start:stop`` of a CSR matrix as a matrix sharing its arrays (no copy).

    The arrays are set on an empty matrix: scipy's constructor from (data, indices,
    indptr) prunes them, which copies any view smaller than half its base array, so the
    two row halves of :func:`row_halves` would copy all of K's entries (260 MB for the
    cow Loop x3's 3D shells) at every product."""
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


def threaded_product(K, X, out: np.ndarray | None = None):
    """K @ X for a CSR matrix K and a dense array or sparse matrix X, the two row halves
    of K on two threads (scipy's products release the GIL and run on one core;
    splitting rows keeps X whole and contiguous).  Sparse X gives a CSR result.  For
    dense X the product can be written into ``out`` (C-contiguous, not overlapping X),
    which saves fresh memory."""
    K = sp.csr_matrix(K)
    if sp.issparse(X):
        X = sp.csr_matrix(X)
        with ThreadPoolExecutor(2) as pool:
            parts = list(pool.map(lambda part: (part[1] @ X).tocsr(), row_halves(K)))
        return sp.vstack(parts, format="csr")
    X = np.ascontiguousarray(X)
    if out is None and (X.ndim == 1 or X.shape[1] < 4 or K.shape[0] < 2):
        return np.asarray(K @ X)
    if out is None:
        out = np.empty((K.shape[0],) + X.shape[1:])
    elif out.shape != (K.shape[0],) + X.shape[1:] or not out.flags.c_contiguous:
        raise ValueError("out must be a C-contiguous array of the product's shape")
    X2 = X.reshape(X.shape[0], -1)
    out2 = out.reshape(out.shape[0], -1)

    same_type = K.dtype == X2.dtype == out2.dtype == np.float64

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


def threaded_transpose_product(P: sp.csr_matrix, Q):
    """``P^T Q`` for a sparse P and a sparse or dense Q with the same rows, as the sum of
    the products of their row halves on two threads: splitting over the inner dimension
    is about twice as fast as over the result's rows.  Dense Q gives a dense result."""
    halves = row_halves(sp.csr_matrix(P))
    if sp.issparse(Q):
        pairs = zip(halves, row_halves(sp.csr_matrix(Q)), strict=True)
        with ThreadPoolExecutor(2) as pool:
            return sum(pool.map(lambda pq: (pq[0][1].T @ pq[1][1]).tocsr(), pairs))
    Q = np.asarray(Q)
    with ThreadPoolExecutor(2) as pool:
        return sum(pool.map(lambda part: np.asarray(part[1].T @ Q[part[0]]), halves))


PROJECTION_ROWS = 1 << 15
"""Rows of K per chunk of :func:`threaded_projection`."""


def chunked_projection(K, P, chunk: int = PROJECTION_ROWS, part: int = 0, parts: int = 1):
    """``P^T K P`` (sparse) as the sum over chunks R of K's rows of ``P[R]^T (K[R] P)``
    (of every ``parts``-th chunk from the ``part``-th: a share of the sum, for threads).
    The whole product ``K P`` (more entries than P itself: each row of K gathers its
    neighbours' rows of P) is never alive at once, only a chunk of it, so the projection
    needs little memory beside P and the result."""
    K = sp.csr_matrix(K)
    P = sp.csr_matrix(P)
    N = K.shape[0]
    total = sp.csr_matrix((P.shape[1], P.shape[1]))
    for start in range(part * chunk, N, parts * chunk):
        rows = slice(start, min(start + chunk, N))
        total = total + (P[rows].T @ (K[rows] @ P)).tocsr()
    return total.tocsr()


def threaded_projection(K, P, chunk: int = PROJECTION_ROWS) -> sp.csr_matrix:
    """:func:`chunked_projection` with the chunks shared by two threads."""
    K, P = sp.csr_matrix(K), sp.csr_matrix(P)
    with ThreadPoolExecutor(2) as pool:
        a, b = pool.map(lambda i: chunked_projection(K, P, chunk, i, 2), (0, 1))
    return (a + b).tocsr()


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b, strict=True)) if isinstance(a, tuple) else a + b


def row_block_sums(K, X: np.ndarray, fn):
    """The sum over K's row blocks R (:data:`ROW_BLOCK` rows) of ``fn(R, K[R] @ X)``, the
    blocks of each half of the rows on a thread of its own: a pass over ``K X`` that holds
    no more than a block of it per thread, where ``threaded_product`` would make a whole
    (N, k) array.  ``fn`` returns an array or a tuple of arrays (summed elementwise, in
    block order within each half) and may write rows R of arrays of its own (the threads
    write disjoint rows).  Halves split at a multiple of ROW_BLOCK (whole 3 x 3 blocks)."""
    K = sp.csr_matrix(K)
    X = np.ascontiguousarray(X)
    N = K.shape[0]
    middle = (N // 2 // ROW_BLOCK) * ROW_BLOCK

    def half(bounds: tuple[int, int]):
        lo, hi = bounds
        total = None
        for start in range(lo, hi, ROW_BLOCK):
            stop = min(start + ROW_BLOCK, hi)
            part = fn(slice(start, stop), np.asarray(csr_rows(K, start, stop) @ X))
            total = part if total is None else _add(total, part)
        return total

    with ThreadPoolExecutor(2) as pool:
        parts = [p for p in pool.map(half, [(0, middle), (middle, N)]) if p is not None]
    return parts[0] if len(parts) == 1 else _add(*parts)


def column_block_products(K, Y: np.ndarray, width: int = 32) -> Iterator[tuple[slice, np.ndarray]]:
    """``(cols, K @ Y[:, cols])`` for consecutive blocks of ``width`` columns, each a
    :func:`threaded_product` (sparse K; other K plain products): passes over ``K Y``
    with (N, width) temporaries instead of an (N, k) one.  50k shells, K times 300
    columns: 1.0 s on one thread, 0.6 s on two."""
    if sp.issparse(K):
        K = sp.csr_matrix(K)
    for start in range(0, Y.shape[1], width):
        cols = slice(start, start + width)
        block = Y[:, cols]
        yield cols, threaded_product(K, block) if sp.issparse(K) else np.asarray(K @ block)


def transform_columns_in_place(Y: np.ndarray, A, chunk: int = 16384, lead: int = 0) -> np.ndarray:
    """``Y A`` for a C-contiguous (N, w) Y and a (w, m) A with m <= w (an int m: Y's
    first m columns), written over Y's own memory: returns a C-contiguous (N, m) array
    on Y's buffer (Y itself is left meaningless).  ``lead`` > 0: the result is
    (N, lead + m) with the product in its columns from ``lead`` on and the first
    ``lead`` left for the caller (uninitialised); ``lead + m <= w``.  Row chunk by
    chunk, so only a chunk of the product is alive: row i of the result ends at
    (i + 1)(lead + m) <= (i + 1) w, so a chunk's writes never reach rows not read yet."""
    n, w = Y.shape
    m = A if isinstance(A, int) else A.shape[1]
    width = lead + m
    if width > w or not Y.flags.c_contiguous:
        raise ValueError("Y must be C-contiguous with at least as many columns as A (plus lead)")
    out = Y.reshape(-1)[: n * width].reshape(n, width)
    for start in range(0, n, chunk):
        rows = slice(start, min(start + chunk, n))
        out[rows, lead:] = Y[rows, :m].copy() if isinstance(A, int) else Y[rows] @ A
    return out
