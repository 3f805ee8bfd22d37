"""The sparse factorisations and the block Krylov-Schur eigensolver on their own."""

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.eigen import DENSE_LIMIT, EigenError, solve_lowest
from modalviewer.core.factor import SPDSolver, available_backends
from modalviewer.core.krylov import block_krylov_schur
from modalviewer.core.primitives import grid_plate


def _spd_matrix(n=400, seed=0):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.01, random_state=rng)
    return (A @ A.T + sp.diags(rng.uniform(0.5, 2.0, n))).tocsr()


@pytest.mark.parametrize("backend", available_backends())
def test_every_backend_solves_one_and_many_right_hand_sides(backend):
    A = _spd_matrix()
    solver = SPDSolver(A, backend=backend)
    assert solver.backend == backend
    rng = np.random.default_rng(1)
    b = rng.standard_normal(A.shape[0])
    B = rng.standard_normal((A.shape[0], 7))
    x, X = solver.solve(b), solver.solve(B)
    assert x.shape == b.shape and X.shape == B.shape
    assert np.linalg.norm(A @ x - b) < 1e-12 * np.linalg.norm(b) * 1e3
    np.testing.assert_allclose(A @ X, B, atol=1e-10)


@pytest.mark.parametrize("backend", available_backends())
def test_every_backend_refuses_an_indefinite_matrix(backend):
    A = _spd_matrix() - 50.0 * sp.eye(400)
    with pytest.raises(np.linalg.LinAlgError):
        SPDSolver(A, backend=backend)


def test_unknown_backend_is_a_clear_error():
    with pytest.raises(ValueError, match="unknown backend"):
        SPDSolver(sp.eye(3), backend="magic")


@pytest.mark.parametrize("block", [3, 8])
def test_block_krylov_schur_against_dense_with_restarts_and_multiplicity(block):
    # A symmetric operator with known spectrum: a triple eigenvalue among the wanted
    # ones and a cluster at the border; the basis is small so the solver must restart.
    rng = np.random.default_rng(7)
    n = 300
    # like a shift-inverted surface spectrum: theta_j ~ 1 / j
    theta_all = 1.0 / (np.arange(1, n + 1) + rng.uniform(0, 0.3, n))
    theta_all[3:6] = theta_all[4]
    U = np.linalg.qr(rng.standard_normal((n, n)))[0]
    A = (U * theta_all) @ U.T
    k = 20
    theta, Y, applied = block_krylov_schur(
        lambda V: A @ V,
        n,
        k,
        keep=k + 4,
        block=block,
        max_basis=k + 4 + 4 * block,
        tol=1e-12,
        report=lambda s, f: None,
    )
    np.testing.assert_allclose(theta, theta_all[:k], rtol=1e-10)
    np.testing.assert_allclose(Y.T @ Y, np.eye(k), atol=1e-12)
    res = np.linalg.norm(A @ Y - Y * theta, axis=0) / theta
    assert res.max() < 1e-10
    assert applied > k + 4 + 4 * block  # it did restart


def test_block_krylov_schur_reports_non_convergence():
    rng = np.random.default_rng(3)
    n = 200
    A = np.diag(np.linspace(1.0, 0.999, n))  # no gap at all
    with pytest.raises(EigenError, match="did not converge"):
        block_krylov_schur(
            lambda V: A @ V @ np.eye(V.shape[1]) + 0 * rng.standard_normal(V.shape),
            n,
            10,
            keep=12,
            block=2,
            max_basis=16,
            tol=1e-14,
            report=lambda s, f: None,
            max_restarts=3,
        )


@pytest.mark.skipif("pardiso" not in available_backends(), reason="MKL PARDISO not installed")
def test_pardiso_and_cholmod_paths_give_the_same_spectrum(monkeypatch):
    plate = grid_plate(40, 40)
    v = plate.vertices.copy()
    v[:, 2] = 0.2 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1])
    mesh = mv.Mesh(v, plate.faces)
    K, mass = operator_matrices(mesh, "shells")
    fast = solve_lowest(K, mass, 60)
    monkeypatch.setenv("MODALVIEWER_NO_PARDISO", "1")
    slow = solve_lowest(K, mass, 60)
    assert "pardiso" in fast.method and "cholmod" in slow.method
    nonzero = fast.eigenvalues > 1e-8 * fast.eigenvalues.max()
    assert nonzero.sum() == 54  # six rigid motions of the free plate
    np.testing.assert_allclose(fast.eigenvalues[nonzero], slow.eigenvalues[nonzero], rtol=1e-9)


def test_shifted_factorisation_of_a_singular_operator_against_dense():
    # the shells Hessian is singular (rigid motions); the solver factors K - shift M
    mesh = grid_plate(12, 12)
    K, mass = operator_matrices(mesh, "shells")
    sparse = solve_lowest(K, mass, 30, dense_limit=0)
    dense = la.eigh(K.toarray(), np.diag(mass), eigvals_only=True, subset_by_index=[0, 29])
    np.testing.assert_allclose(sparse.eigenvalues, dense, atol=1e-9 * dense.max())


def test_more_than_half_of_the_spectrum():
    # 1296 unknowns (just above DENSE_LIMIT): 760 modes still fit a Krylov basis (more
    # than N / 2 wanted; 790 is the most that fit), 1000 do not and the dense solver
    # takes over; both agree with a dense reference
    mesh = grid_plate(35, 35)
    K, mass = operator_matrices(mesh, "laplacian")
    assert DENSE_LIMIT < K.shape[0] < 2 * 760
    dense = la.eigh(K.toarray(), np.diag(mass), eigvals_only=True, subset_by_index=[0, 999])
    krylov = solve_lowest(K, mass, 760)
    assert krylov.method.startswith("shift-invert")
    np.testing.assert_allclose(krylov.eigenvalues, dense[:760], atol=1e-9 * dense.max())
    fallback = solve_lowest(K, mass, 1000)
    assert fallback.method == "dense"
    np.testing.assert_allclose(fallback.eigenvalues, dense, atol=1e-9 * dense.max())


@pytest.mark.parametrize("local", [0, 40])
def test_orthonormal_block_against_the_basis(local):
    """W = Q h + V Rn with V orthonormal and orthogonal to Q, also when the first pass
    only covers the columns from ``local`` on and W has rounding-size components along
    the others (as in the Lanczos recurrence)."""
    from modalviewer.core.krylov import _orthonormal_block

    rng = np.random.default_rng(7)
    N, m, b = 3000, 56, 8
    Q = np.linalg.qr(rng.standard_normal((N, m)))[0]
    coupling = rng.standard_normal((m, b)) * 1e3
    coupling[:local] *= 1e-13  # nearly orthogonal to the leading columns
    W = Q @ coupling + 1e-3 * rng.standard_normal((N, b))
    V, h, Rn = _orthonormal_block(W.copy(), Q, rng, local)
    assert np.abs(Q @ h + V @ Rn - W).max() < 1e-10 * np.abs(W).max()
    assert np.abs(Q.T @ V).max() < 1e-13
    assert np.abs(V.T @ V - np.eye(b)).max() < 1e-13


def test_solver_accounts_for_its_time_and_operator_columns(monkeypatch):
    import time

    plate = grid_plate(40, 40)
    K, mass = operator_matrices(plate, "laplacian")
    calls = []
    original = SPDSolver.solve

    def counting_solve(self, b):
        calls.append(b.shape[1] if b.ndim == 2 else 1)
        return original(self, b)

    monkeypatch.setattr(SPDSolver, "solve", counting_solve)
    start = time.perf_counter()
    result = solve_lowest(K, mass, 40)
    wall = time.perf_counter() - start
    stages = result.stage_seconds
    for name in ("factorisation", "solves", "orthogonalisation", "ritz", "refinement"):
        assert stages[name] > 0.0
    assert sum(stages.values()) <= wall
    # every column the factor solved for is counted, the refinement's 40 included
    assert result.operator_columns == sum(calls)
    assert result.operator_columns >= 2 * 40


@pytest.mark.parametrize("mixing", ["scaled", "ill-conditioned"])
def test_final_rayleigh_ritz_in_a_non_orthonormal_basis(mixing, monkeypatch):
    # the span of 12 exact eigenvectors (standard form), given as scaled columns (what
    # inverse iteration produces) or mixed with condition number 1e6 (the fallback that
    # orthonormalises first): exact eigenvalues and Mass-orthonormal vectors either way
    from modalviewer.core import eigen
    from modalviewer.core.eigen import _rayleigh_ritz_in_place

    orthonormalised = []
    original = eigen.cholqr_in_place
    monkeypatch.setattr(
        eigen, "cholqr_in_place", lambda Y: orthonormalised.append(1) or original(Y)
    )
    rng = np.random.default_rng(5)
    K = _spd_matrix(200, seed=4)
    mass = rng.uniform(0.5, 2.0, 200)
    lam, X = la.eigh(K.toarray(), np.diag(mass))
    Y = np.sqrt(mass)[:, None] * X[:, :12]
    if mixing == "scaled":
        Y = Y * np.logspace(0, 6, 12)
    else:
        U = np.linalg.qr(rng.standard_normal((12, 12)))[0]
        Y = Y @ (U * np.logspace(0, -6, 12)) @ U.T
    Y = np.asfortranarray(Y)
    ritz = _rayleigh_ritz_in_place(K, 1.0 / np.sqrt(mass), Y)
    assert bool(orthonormalised) == (mixing == "ill-conditioned")
    np.testing.assert_allclose(ritz, lam[:12], rtol=1e-9)
    np.testing.assert_allclose((Y * mass[:, None]).T @ Y, np.eye(12), atol=1e-9)
    res = np.linalg.norm(K @ Y - (mass[:, None] * Y) * ritz, axis=0) / ritz
    assert res.max() < 1e-9


@pytest.mark.parametrize("order", ["C", "F"])
def test_sign_convention_largest_entry_positive(order):
    from modalviewer.core.eigen import _fix_signs

    rng = np.random.default_rng(2)
    X = np.asarray(rng.standard_normal((5000, 40)), order=order)
    expected = X * np.sign(X[np.abs(X).argmax(axis=0), np.arange(40)])
    fixed = _fix_signs(X.copy(order=order), rows=700)  # blocks of rows, the last one short
    np.testing.assert_array_equal(fixed, expected)
    assert np.all(fixed[np.abs(fixed).argmax(axis=0), np.arange(40)] > 0)


def test_pardiso_stores_vertex_blocks_as_blocks_and_scalar_operators_plainly():
    from modalviewer.core.factor import has_vertex_blocks

    if "pardiso" not in available_backends():
        pytest.skip("block storage is PARDISO's")
    spot = mv.load_mesh(mv.asset_path("spot.obj"))  # curved: its 3 x 3 blocks are full
    plate = grid_plate(41)  # 462 vertices: a Laplacian whose rows also come in threes
    rng = np.random.default_rng(3)
    for mesh, operator, blocks in ((spot, "shells", True), (plate, "laplacian", False)):
        K, mass = operator_matrices(mesh, operator)
        A = sp.csr_matrix(K + 1e-3 * float(np.median(K.diagonal() / mass)) * sp.diags(mass))
        assert has_vertex_blocks(A) == blocks
        solver = SPDSolver(A, backend="pardiso")
        assert solver._impl._iparm[36] == (-80 if blocks else 0)
        B = rng.standard_normal((A.shape[0], 4))
        X = solver.solve(B)
        assert np.linalg.norm(A @ X - B) <= 1e-10 * np.linalg.norm(B)
    # rows of one group with different columns are not blocks
    M = sp.csr_matrix(np.eye(6) + np.diag([0.1] * 5, 1) + np.diag([0.1] * 5, -1))
    assert not has_vertex_blocks(M)
    assert not has_vertex_blocks(sp.identity(7, format="csr"))
