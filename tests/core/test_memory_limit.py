"""The exact solver within a memory limit: the factor out of core where it does not fit,
the modes written over the Krylov basis, and the limit's setting."""

import gc
import os
import tracemalloc

import numpy as np
import pytest
import scipy.sparse as sp

from modalviewer.core import factor as factor_module
from modalviewer.core.eigen import solve_lowest
from modalviewer.core.factor import SPDSolver, available_backends
from modalviewer.core.memory import MEMORY_LIMIT_SHARE, memory_limit_mb, physical_memory_mb
from modalviewer.core.products import move_columns_in_place

needs_pardiso = pytest.mark.skipif(
    "pardiso" not in available_backends(), reason="out of core is PARDISO's (the mkl wheel)"
)


def _laplacian_3d(m: int) -> sp.csr_matrix:
    """The 7-point Laplacian of an m^3 grid (Dirichlet boundary): its factor fills in far
    more than a surface operator's, so out of core pays from 64k unknowns."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    eye = sp.identity(m)
    terms = [sp.kron(sp.kron(T, eye), eye), sp.kron(sp.kron(eye, T), eye)]
    return (terms[0] + terms[1] + sp.kron(eye, sp.kron(eye, T))).tocsr()


def _analytic_lowest(m: int, k: int) -> np.ndarray:
    one = 2.0 - 2.0 * np.cos(np.pi * np.arange(1, m + 1) / (m + 1))
    return np.sort((one[:, None, None] + one[None, :, None] + one[None, None, :]).ravel())[:k]


@needs_pardiso
def test_a_factor_over_the_budget_goes_to_a_file_and_solves_the_same(tmp_path, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_FACTOR_DIR", str(tmp_path))
    A = _laplacian_3d(40)  # 64 000 unknowns, a 127 MB factor
    in_core = SPDSolver(A)
    assert not in_core.out_of_core and in_core.factor_mb > 100
    assert not list(tmp_path.iterdir())
    ooc = SPDSolver(A, memory_budget_mb=0.5 * in_core.factor_mb)
    assert ooc.out_of_core
    (folder,) = tmp_path.iterdir()
    written = sum(f.stat().st_size for f in folder.iterdir()) / 2**20
    assert written > 0.5 * in_core.factor_mb  # the factor is in the file
    # PARDISO's environment settings are the factorisation's only
    assert not any(name.startswith("MKL_PARDISO_OOC") for name in os.environ)
    B = np.random.default_rng(0).standard_normal((A.shape[0], 5))
    X, X_ooc = in_core.solve(B), ooc.solve(B)
    assert np.linalg.norm(A @ X_ooc - B) <= 1e-10 * np.linalg.norm(B)
    np.testing.assert_allclose(X_ooc, X, rtol=0, atol=1e-12 * np.abs(X).max())
    del ooc
    gc.collect()
    assert not list(tmp_path.iterdir())  # the file goes with the factor
    assert not SPDSolver(A, memory_budget_mb=2 * in_core.factor_mb).out_of_core


@needs_pardiso
def test_out_of_core_solves_run_on_one_mkl_thread_and_give_the_threads_back(tmp_path, monkeypatch):
    """PARDISO's parallel substitution reads a factor file many times slower than one
    thread (benchmarks/out_of_core_threads.py): an out-of-core solve runs on one MKL
    thread, an in-core one on MKL's own count, and the count is the same after."""
    monkeypatch.setenv("MODALVIEWER_FACTOR_DIR", str(tmp_path))
    lib = factor_module._load_mkl()
    A = _laplacian_3d(40)  # 64 000 unknowns
    B = np.random.default_rng(1).standard_normal((A.shape[0], 3))
    seen = []
    real_call = factor_module._Pardiso._call

    def call(self, phase, b):
        if phase == 33:
            seen.append((self.out_of_core, lib.MKL_Get_Max_Threads()))
        return real_call(self, phase, b)

    monkeypatch.setattr(factor_module._Pardiso, "_call", call)
    previous = lib.MKL_Set_Num_Threads_Local(2)
    try:
        in_core = SPDSolver(A)
        ooc = SPDSolver(A, memory_budget_mb=0.5 * in_core.factor_mb)
        assert ooc.out_of_core and not in_core.out_of_core
        X, X_ooc = in_core.solve(B), ooc.solve(B)
        after = lib.MKL_Get_Max_Threads()
    finally:
        lib.MKL_Set_Num_Threads_Local(previous)
    assert seen == [(False, 2), (True, 1)]
    assert after == 2
    np.testing.assert_allclose(X_ooc, X, rtol=0, atol=1e-12 * np.abs(X).max())


@needs_pardiso
def test_a_factor_stays_in_core_where_the_disk_has_no_room(tmp_path, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_FACTOR_DIR", str(tmp_path))

    class Full:
        free = 100 * 2**20

    monkeypatch.setattr(factor_module.shutil, "disk_usage", lambda path: Full())
    solver = SPDSolver(_laplacian_3d(40), memory_budget_mb=10.0)
    assert not solver.out_of_core and not list(tmp_path.iterdir())


@needs_pardiso
def test_solve_lowest_within_a_small_limit_gives_the_same_spectrum_out_of_core(monkeypatch):
    from modalviewer.core import eigen

    # the basis stays in double precision here (its single-precision form has a test below)
    monkeypatch.setattr(eigen, "basis_in_float32", lambda *args: False)
    m, k = 40, 24
    A = _laplacian_3d(m)
    mass = np.ones(A.shape[0])
    free = solve_lowest(A, mass, k, memory_limit_mb=1e9)
    tight = solve_lowest(A, mass, k, memory_limit_mb=1.0)
    assert not free.out_of_core and "out of core" not in free.method
    assert tight.out_of_core and "factor out of core" in tight.method
    exact = _analytic_lowest(m, k)
    for result in (free, tight):
        np.testing.assert_allclose(result.eigenvalues, exact, rtol=1e-10)
        assert result.residuals.max() < 1e-8
        gram = result.vectors.T @ (mass[:, None] * result.vectors)
        assert np.abs(gram - np.eye(k)).max() < 1e-12
    np.testing.assert_allclose(tight.eigenvalues, free.eigenvalues, rtol=1e-12)


def _laplacian_2d(m: int) -> sp.csr_matrix:
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(m, m))
    eye = sp.identity(m)
    return (sp.kron(T, eye) + sp.kron(eye, T)).tocsr()


def test_the_modes_are_written_over_the_krylov_basis_not_beside_it(monkeypatch):
    # 60 modes of a 130k-unknown problem (59 MB): the last stage ("copy") makes the
    # row-major modes array; a new array beside the basis would add all of them
    from contextlib import contextmanager

    from modalviewer.core import eigen

    grown = {}
    original = eigen.StageTimer.__call__

    @contextmanager
    def measured(self, stage):
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        with original(self, stage):
            yield
        if stage == "copy":
            grown["copy"] = (tracemalloc.get_traced_memory()[1] - before) / 2**20

    monkeypatch.setattr(eigen.StageTimer, "__call__", measured)
    m, k = 360, 60
    A = _laplacian_2d(m)
    n = A.shape[0]
    modes_mb = 8.0 * n * k / 2**20
    tracemalloc.start()
    try:
        result = solve_lowest(A, np.ones(n), k, memory_limit_mb=1e9)
    finally:
        tracemalloc.stop()
    assert grown["copy"] < 0.25 * modes_mb, (grown, modes_mb)  # row chunks only: 7.5 MB
    assert result.vectors.flags.c_contiguous and result.vectors.flags.owndata
    assert result.vectors.shape == (n, k)
    one = 2.0 - 2.0 * np.cos(np.pi * np.arange(1, m + 1) / (m + 1))
    exact = np.sort((one[:, None] + one[None, :]).ravel())[:k]
    np.testing.assert_allclose(result.eigenvalues, exact, rtol=1e-9)
    gram = result.vectors.T @ result.vectors
    assert np.abs(gram - np.eye(k)).max() < 1e-12


def test_move_columns_in_place_moves_the_first_columns_behind_a_lead():
    rng = np.random.default_rng(3)
    B = rng.standard_normal((1000, 9))
    expected = B[:, :5].copy()
    address = B.__array_interface__["data"][0]
    out = move_columns_in_place(B, 5, chunk=7, lead=2)  # several chunks
    assert out.shape == (1000, 7) and out.flags.c_contiguous
    assert out.__array_interface__["data"][0] == address  # B's own memory
    np.testing.assert_array_equal(out[:, 2:], expected)
    with pytest.raises(ValueError, match=r"lead \+ m columns"):
        move_columns_in_place(rng.standard_normal((10, 4)), 3, lead=2)


def test_the_memory_limit_is_half_the_machine_or_the_setting(monkeypatch):
    monkeypatch.delenv("MODALVIEWER_MEMORY_LIMIT_MB", raising=False)
    physical = physical_memory_mb()
    assert physical and memory_limit_mb() == pytest.approx(MEMORY_LIMIT_SHARE * physical)
    monkeypatch.setenv("MODALVIEWER_MEMORY_LIMIT_MB", "3000")
    assert memory_limit_mb() == 3000.0
    for bad in ("lots", "-5", "0"):
        monkeypatch.setenv("MODALVIEWER_MEMORY_LIMIT_MB", bad)
        with pytest.raises(ValueError, match="MODALVIEWER_MEMORY_LIMIT_MB"):
            memory_limit_mb()


def test_folders_of_ended_processes_are_removed_and_live_ones_kept(tmp_path):
    import subprocess
    import sys

    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)  # fmt: skip
    dead_pid = int(ended.stdout)
    stale = tmp_path / f"{factor_module.FOLDER_PREFIX}{dead_pid}-abc"
    live = tmp_path / f"{factor_module.FOLDER_PREFIX}{os.getpid()}-def"
    other = tmp_path / "something-else"
    for folder in (stale, live, other):
        folder.mkdir()
        (folder / "mkl_pardiso_lnz_0_0.bin").write_bytes(b"0" * 10)
    removed = factor_module.remove_stale_factor_folders(str(tmp_path))
    assert removed == [str(stale)]
    assert not stale.exists() and live.exists() and other.exists()


def test_rounding_floors_of_chosen_columns_copy_32_columns_at_a_time():
    # the residual check looks at the rounding floors of the modes above 1e-8: on fine
    # shells meshes most of them, where a copy of those columns and of their absolute
    # values made the end of a big solve its peak (2 x 3 GB at 427k vertices, 300 modes)
    from modalviewer.core.eigen import rounding_floors

    n, k = 20_000, 800
    rng = np.random.default_rng(5)
    K = _laplacian_3d(28)[:n, :n]
    mass = rng.uniform(0.5, 2.0, n)
    X = rng.standard_normal((n, k))
    lam = rng.uniform(1.0, 2.0, k)
    chosen = np.arange(3, k, 2)  # 399 columns
    expected = rounding_floors(K, mass, lam[chosen], X[:, chosen].copy())
    tracemalloc.start()
    try:
        floors = rounding_floors(K, mass, lam[chosen], X, columns=chosen)
        peak_mb = tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
    np.testing.assert_allclose(floors, expected, rtol=1e-14)
    chosen_mb = 8.0 * n * chosen.size / 2**20  # 61 MB; the (N, 32) blocks: about 25 MB
    assert peak_mb < 0.5 * chosen_mb, (peak_mb, chosen_mb)


def test_the_modes_are_right_when_the_basis_cannot_be_shrunk_in_place(monkeypatch):
    # another reference to the basis makes numpy refuse to resize it: the packed modes
    # are copied out instead
    from modalviewer.core import eigen

    A = _laplacian_2d(60)
    mass = np.ones(A.shape[0])
    reference = solve_lowest(A, mass, 20, memory_limit_mb=1e9)
    held = []
    original = eigen._shift_invert

    def holding(*args):
        result = original(*args)
        held.append(result[1])
        return result

    monkeypatch.setattr(eigen, "_shift_invert", holding)
    result = solve_lowest(A, mass, 20, memory_limit_mb=1e9)
    assert held and result.vectors.flags.owndata and result.vectors.shape == (3600, 20)
    np.testing.assert_array_equal(result.vectors, reference.vectors)
    np.testing.assert_array_equal(result.eigenvalues, reference.eigenvalues)


@needs_pardiso
def test_a_failed_out_of_core_factorisation_falls_back_to_core(tmp_path, monkeypatch):
    # a working buffer below PARDISO's minimum makes the out-of-core factorisation fail
    # (error -2); the factor is then made in core instead of being reported indefinite
    monkeypatch.setenv("MODALVIEWER_FACTOR_DIR", str(tmp_path))
    monkeypatch.setattr(factor_module, "OUT_OF_CORE_MARGIN", 0.2)
    monkeypatch.setattr(factor_module, "OUT_OF_CORE_EXTRA_MB", 0.0)
    A = _laplacian_3d(40)
    solver = SPDSolver(A, memory_budget_mb=1.0)
    assert not solver.out_of_core
    assert not list(tmp_path.iterdir())  # its folder is gone
    B = np.random.default_rng(1).standard_normal((A.shape[0], 3))
    assert np.linalg.norm(A @ solver.solve(B) - B) <= 1e-10 * np.linalg.norm(B)


def _traced_peak_mb(solve) -> tuple[float, object]:
    """The peak of numpy's traced allocations (PARDISO's memory is not traced) during
    ``solve()``, and its result."""
    gc.collect()
    tracemalloc.start()
    try:
        result = solve()
        return tracemalloc.get_traced_memory()[1] / 2**20, result
    finally:
        tracemalloc.stop()


def test_a_basis_that_does_not_fit_is_kept_in_single_precision(monkeypatch):
    from modalviewer.core import eigen

    m, k = 240, 40  # 57 600 unknowns, a 2D Laplacian with known eigenvalues
    A = _laplacian_2d(m)
    n = A.shape[0]
    mass = np.full(n, 0.5)
    chosen = []
    real_rule = eigen.basis_in_float32

    def rule(*args):
        chosen.append(real_rule(*args))
        return chosen[-1]

    monkeypatch.setattr(eigen, "basis_in_float32", rule)
    double_mb, free = _traced_peak_mb(lambda: solve_lowest(A, mass, k, memory_limit_mb=1e9))
    single_mb, tight = _traced_peak_mb(lambda: solve_lowest(A, mass, k, memory_limit_mb=1.0))
    assert chosen == [False, True]
    assert not free.basis_float32 and tight.basis_float32
    assert "single-precision Krylov basis" in tight.method
    assert "single-precision" not in free.method
    one = 2.0 - 2.0 * np.cos(np.pi * np.arange(1, m + 1) / (m + 1))
    exact = np.sort((one[:, None] + one[None, :]).ravel())[:k] / 0.5
    np.testing.assert_allclose(free.eigenvalues, exact, rtol=1e-10)
    # the float64 step of inverse iteration and Rayleigh-Ritz: eigenvalues to 1e-10 even
    # though the basis was orthonormal only to about 1e-7; residuals about 1e-7
    np.testing.assert_allclose(tight.eigenvalues, exact, rtol=1e-10)
    assert tight.residuals.max() < 1e-6
    X = tight.vectors
    assert X.dtype == np.float64 and X.shape == (n, k)
    assert X.flags.c_contiguous and X.flags.owndata
    gram = X.T @ (mass[:, None] * X)
    assert np.abs(gram - np.eye(k)).max() < 1e-12
    # the basis (N, 96) in float32 is about 4.7 instead of 9.4 MB per 10k rows, and the
    # modes are written into its memory: the whole solve's arrays need much less
    basis_columns = eigen.krylov_sizes(k, n)[2] + eigen.krylov_sizes(k, n)[1]
    saved_mb = 8.0 * n * basis_columns / 2**20 - eigen.float32_basis_mb(n, basis_columns, k)
    assert saved_mb > 15
    assert single_mb < double_mb - 0.7 * saved_mb, (single_mb, double_mb, saved_mb)


def test_the_basis_is_single_precision_only_where_double_does_not_fit():
    from modalviewer.core.memory import basis_in_float32, float32_basis_mb

    n, width, out, block = 3_000_000, 464, 300, 16
    assert not basis_in_float32(None, n, width, out, block)
    assert not basis_in_float32(1e9, n, width, out, block)
    assert basis_in_float32(1.0, n, width, out, block)
    # the buffer holds the float32 basis, then the float64 modes: the larger of the two
    assert float32_basis_mb(n, width, out) == pytest.approx(8.0 * n * out / 2**20)
    assert float32_basis_mb(n, width, 100) == pytest.approx(4.0 * n * width / 2**20)
    # where the modes alone would be as large as the double-precision basis: no gain
    assert not basis_in_float32(1.0, 1000, 20, 20, 4)


@pytest.mark.parametrize("width, count, out_width", [(10, 6, 7), (40, 6, 8), (9, 9, 9)])
def test_widening_a_single_precision_basis_in_place_keeps_its_columns(width, count, out_width):
    from modalviewer.core.eigen import _widen_in_place

    n = 10_007  # several blocks of rows, the last one short
    buffer = np.empty(max(n * out_width, -(-n * width // 2)))
    single = buffer.view(np.float32)[: n * width].reshape(n, width)
    single[:] = np.random.default_rng(1).standard_normal((n, width))
    expected = single[:, :count].astype(np.float64)
    del single
    _widen_in_place(buffer, n, width, count, out_width)
    widened = buffer[: n * out_width].reshape(n, out_width)
    np.testing.assert_array_equal(widened[:, :count], expected)


def test_products_with_a_single_precision_basis_are_formed_in_double_precision():
    from modalviewer.core.krylov import _basis_t_times, _subtract_basis_times

    rng = np.random.default_rng(2)
    Q = rng.standard_normal((5000, 30)).astype(np.float32)
    W = np.asfortranarray(rng.standard_normal((5000, 4)))
    Q64 = Q.astype(np.float64)
    h = _basis_t_times(Q, W)
    assert h.dtype == np.float64
    np.testing.assert_allclose(h, Q64.T @ W, rtol=1e-13, atol=1e-12)
    expected = W - Q64 @ h
    _subtract_basis_times(W, Q, h)
    np.testing.assert_allclose(W, expected, rtol=1e-13, atol=1e-12)
