"""Sparse products on the machine's two cores.

scipy's sparse products release the GIL but run on one core; splitting the rows of the
left factor over two threads halves their time on two cores.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.sparse as sp

__all__ = ["row_halves", "threaded_product", "threaded_transpose_product"]


def row_halves(K: sp.csr_matrix) -> list[tuple[slice, sp.csr_matrix]]:
    """The two row halves of a CSR matrix as matrices sharing its arrays (no copy)."""
    N = K.shape[0]
    h = N // 2
    p = K.indptr
    top = sp.csr_matrix((K.data[: p[h]], K.indices[: p[h]], p[: h + 1]), shape=(h, K.shape[1]))
    bottom = sp.csr_matrix(
        (K.data[p[h] :], K.indices[p[h] :], p[h:] - p[h]), shape=(N - h, K.shape[1])
    )
    return [(slice(0, h), top), (slice(h, N), bottom)]


def threaded_product(K, X):
    """K @ X for a CSR matrix K and a dense array or sparse matrix X, the two row halves
    of K on two threads (scipy's products release the GIL and run on one core;
    splitting rows keeps X whole and contiguous).  Sparse X gives a CSR result."""
    K = sp.csr_matrix(K)
    if sp.issparse(X):
        X = sp.csr_matrix(X)
        with ThreadPoolExecutor(2) as pool:
            parts = list(pool.map(lambda part: (part[1] @ X).tocsr(), row_halves(K)))
        return sp.vstack(parts, format="csr")
    X = np.ascontiguousarray(X)
    if X.ndim == 1 or X.shape[1] < 4 or K.shape[0] < 2:
        return np.asarray(K @ X)
    out = np.empty((K.shape[0], X.shape[1]))

    def rows(part: tuple[slice, sp.csr_matrix]) -> None:
        out[part[0]] = part[1] @ X

    with ThreadPoolExecutor(2) as pool:
        list(pool.map(rows, row_halves(K)))
    return out


def threaded_transpose_product(P: sp.csr_matrix, Q: sp.csr_matrix) -> sp.csr_matrix:
    """``P^T Q`` for two sparse matrices with the same rows, as the sum of the products
    of their row halves on two threads: splitting over the inner dimension is twice as
    fast as over the result's rows (130k shells preview, 1803 functions: 3.0-4.3 s
    against 6.2-6.7 s)."""
    pairs = zip(row_halves(sp.csr_matrix(P)), row_halves(sp.csr_matrix(Q)), strict=True)
    with ThreadPoolExecutor(2) as pool:
        return sum(pool.map(lambda pq: (pq[0][1].T @ pq[1][1]).tocsr(), pairs))
