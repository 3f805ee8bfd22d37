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
    must be views, and K @ X must allocate little beyond its result."""
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
    X = np.ones((4000, 8))
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    threaded_product(A, X)
    peak = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    assert peak < X.nbytes + 0.1 * (A.data.nbytes + A.indices.nbytes), peak


def test_threaded_product_of_other_dtypes_takes_the_generic_path(K):
    X = np.random.default_rng(1).standard_normal((301, 5))
    got = threaded_product(K, X.astype(np.float32))
    np.testing.assert_allclose(got, K @ X, rtol=1e-4, atol=1e-4)


def test_move_columns_in_place_keeps_the_first_columns():
    from modalviewer.core.products import move_columns_in_place

    Y = np.arange(600.0).reshape(100, 6)
    expected = Y[:, :4].copy()
    out = move_columns_in_place(Y, 4, chunk=7)
    assert out.flags.c_contiguous and np.shares_memory(out, Y)
    np.testing.assert_array_equal(out, expected)
    with pytest.raises(ValueError, match="columns"):
        move_columns_in_place(np.ones((4, 2)), 3)
