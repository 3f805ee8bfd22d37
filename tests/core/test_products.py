"""Sparse products on two threads (core.products)."""

import numpy as np
import pytest
import scipy.sparse as sp

from modalviewer.core.products import threaded_product


@pytest.fixture(scope="module")
def K():
    A = sp.random(301, 301, density=0.05, random_state=0, format="csr")
    return (A + A.T).tocsr()


def test_threaded_product_equals_the_plain_product(K):
    X = np.random.default_rng(0).standard_normal((301, 7))
    np.testing.assert_allclose(threaded_product(K, X), K @ X, rtol=1e-13, atol=1e-13)
    S = sp.random(301, 40, density=0.1, random_state=1, format="csr")
    np.testing.assert_allclose(threaded_product(K, S).toarray(), (K @ S).toarray(), atol=1e-13)


def test_row_halves_share_the_matrix_arrays_and_the_product_copies_none_of_them():
    """scipy's constructor would copy a view under half its base array: the halves of K
    must be views, and K @ X into ``out`` must allocate far less than K's entries."""
    import tracemalloc

    from modalviewer.core.products import csr_rows, row_halves

    A = sp.random(4000, 4000, density=0.01, random_state=2, format="csr")
    halves = row_halves(A)
    for rows, half in halves:
        assert np.shares_memory(half.data, A.data) and np.shares_memory(half.indices, A.indices)
        np.testing.assert_array_equal(half.toarray(), A[rows].toarray())
    unsorted = sp.csr_matrix((np.ones(3), np.array([2, 0, 1]), np.array([0, 3, 3])), (2, 3))
    unsorted.has_sorted_indices = False
    assert not csr_rows(unsorted, 0, 2).has_sorted_indices
    X, out = np.ones((4000, 8)), np.empty((4000, 8))
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    threaded_product(A, X, out=out)
    peak = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    assert peak < 0.1 * (A.data.nbytes + A.indices.nbytes), peak


def test_threaded_product_writes_into_out(K):
    X = np.random.default_rng(1).standard_normal((301, 5))
    out = np.full((301, 5), np.nan)  # old contents must not leak into the result
    got = threaded_product(K, X, out=out)
    assert got is out
    np.testing.assert_allclose(out, K @ X, rtol=1e-13, atol=1e-13)
    # other dtypes take the generic path
    out32 = np.empty((301, 5), dtype=np.float32)
    threaded_product(K, X.astype(np.float32), out=out32)
    np.testing.assert_allclose(out32, K @ X, rtol=1e-4, atol=1e-4)
    with pytest.raises(ValueError, match="C-contiguous"):
        threaded_product(K, X, out=np.empty((5, 301)).T)


@pytest.mark.parametrize("shape", [(1000, 7, 5), (1000, 7, 7), (50000, 30, 12)])
def test_transform_columns_in_place_is_the_product_on_the_same_memory(shape):
    """Small chunks (every chunk's writes overlap rows of the chunk being read) and
    a float32 Y as a single-precision Krylov basis holds it."""
    from modalviewer.core.products import transform_columns_in_place

    n, w, m = shape
    rng = np.random.default_rng(1)
    Y = rng.standard_normal((n, w)).astype(np.float32)
    A = rng.standard_normal((w, m))
    expected = Y.astype(np.float64) @ A
    base = Y.ctypes.data
    out = transform_columns_in_place(Y, A, chunk=97)
    assert out.shape == (n, m) and out.flags.c_contiguous and out.ctypes.data == base
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-5 * np.abs(expected).max())
    with pytest.raises(ValueError, match="columns"):
        transform_columns_in_place(np.ones((4, 2)), np.ones((2, 3)))


def test_transform_columns_in_place_keeps_the_first_columns_for_an_int():
    from modalviewer.core.products import transform_columns_in_place

    Y = np.arange(600.0).reshape(100, 6)
    expected = Y[:, :4].copy()
    out = transform_columns_in_place(Y, 4, chunk=7)
    assert out.flags.c_contiguous and np.shares_memory(out, Y)
    np.testing.assert_array_equal(out, expected)
