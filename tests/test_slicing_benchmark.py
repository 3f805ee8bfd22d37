"""benchmarks/sliced_solver.py, the spectrum-slicing solver the performance page measures
against the library's: the same pairs, each band checked by the factor's inertia."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.eigen import relative_residuals, solve_lowest
from modalviewer.core.factor import available_backends
from modalviewer.core.nullspace import null_space
from modalviewer.core.operators import operator_info

pytestmark = pytest.mark.skipif(
    "pardiso" not in available_backends(), reason="the sliced solver needs MKL PARDISO"
)


def test_sliced_pairs_equal_the_single_shift_ones():
    from benchmarks.sliced_solver import sliced_lowest

    mesh = mv.load_mesh(mv.asset_path("spot.obj"))
    info = operator_info("shells")
    K, mass = operator_matrices(mesh, info, 1.0, 1.0)
    nulls = null_space(mesh, info, K, mass)
    single = solve_lowest(K, mass, 60, null_space=nulls.vectors)
    lam, X, _, _, bands = sliced_lowest(K, mass, 60, 3, nulls.vectors)
    assert len(bands) >= 3
    for band in bands[1:]:  # Sylvester: eigenvalues below the shift, found and counted
        assert band["found_below"] == band["inertia_below"]
    assert np.all(lam[:6] == 0.0) and np.all(np.diff(lam[6:]) > 0)
    rel = np.abs(lam[6:] - single.eigenvalues[6:]) / single.eigenvalues[6:]
    assert rel.max() <= 1e-8
    gram = X.T @ (mass[:, None] * X)
    assert np.abs(gram - np.eye(60)).max() <= 1e-8  # bands' modes Mass-orthonormal
    assert relative_residuals(K, mass, lam[6:], X[:, 6:]).max() <= 1e-8
