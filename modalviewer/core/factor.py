"""Sparse symmetric positive definite factorisations: factor once, solve many right-hand sides.

Backends, fastest first (``backend="auto"`` takes the first available): ``"pardiso"``
(Intel MKL PARDISO through ``ctypes``: parallel METIS ordering and solves),
``"cholmod"`` (``cholespy``), ``"superlu"`` (scipy, always there).  Given
``memory_budget_mb``, PARDISO writes a factor that does not fit to a temporary folder
(out of core: less memory, slower solves; "Memory of big exact solves" in
docs/performance.md); the others ignore the budget.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import importlib.util
import os
import shutil
import sys
import tempfile
import threading
import weakref
from contextlib import contextmanager, nullcontext

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


@functools.cache
def _load_mkl():
    """The MKL runtime library shipped by the ``mkl`` wheel, or None."""
    candidates = [os.environ["MODALVIEWER_MKL_RT"]] if os.environ.get("MODALVIEWER_MKL_RT") else []
    for prefix in dict.fromkeys([sys.prefix, sys.base_prefix]):
        candidates += sorted(glob.glob(os.path.join(prefix, "lib", "libmkl_rt.so*")), key=len)
    for path in candidates:
        try:
            lib = ctypes.CDLL(path)
            lib.pardiso.restype = None
        except (OSError, AttributeError):
            continue
        return lib
    return None


def available_backends() -> list[str]:
    """Backends usable in this environment, fastest first."""
    names = []
    if os.environ.get("MODALVIEWER_NO_PARDISO") != "1" and _load_mkl() is not None:
        names.append("pardiso")
    if importlib.util.find_spec("cholespy") is not None:
        names.append("cholmod")
    names.append("superlu")
    return names


# The out-of-core working buffer: OUT_OF_CORE_MARGIN times PARDISO's stated minimum
# (``iparm[15] + iparm[62]`` KB) plus OUT_OF_CORE_EXTRA_MB; with exactly the minimum the
# factorisation can fail for lack of memory (error -2).
OUT_OF_CORE_MARGIN = 1.1
OUT_OF_CORE_EXTRA_MB = 64.0

# PARDISO reads its out-of-core settings from the environment: one factorisation at a time
_OOC_ENVIRONMENT = threading.Lock()


@contextmanager
def _out_of_core_environment(folder: str, buffer_mb: float):
    """PARDISO's out-of-core settings in the environment while the block runs."""
    settings = {
        "MKL_PARDISO_OOC_PATH": folder,
        "MKL_PARDISO_OOC_MAX_CORE_SIZE": str(int(buffer_mb)),
        "MKL_PARDISO_OOC_KEEP_FILE": "0",
    }
    with _OOC_ENVIRONMENT:
        saved = {key: os.environ.get(key) for key in settings}
        os.environ.update(settings)
        try:
            yield
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value


FOLDER_PREFIX = "modalviewer-factor-"


def factor_folder() -> str:
    """Where out-of-core factors go: ``MODALVIEWER_FACTOR_DIR``, else the temporary folder."""
    return os.environ.get("MODALVIEWER_FACTOR_DIR") or tempfile.gettempdir()


def remove_stale_factor_folders(parent: str | None = None) -> list[str]:
    """Remove (and return) the factor folders in ``parent`` whose process has ended: a
    stopped computation process cannot remove its own."""
    parent = parent or factor_folder()
    removed = []
    try:
        names = os.listdir(parent)
    except OSError:
        return removed
    for name in names:
        pid_text = name[len(FOLDER_PREFIX) :].split("-", 1)[0]
        if not name.startswith(FOLDER_PREFIX) or not pid_text.isdigit():
            continue
        try:
            os.kill(int(pid_text), 0)
        except ProcessLookupError:  # ended (any other error: alive, or not ours to see)
            path = os.path.join(parent, name)
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
        except OSError:
            pass
    return removed


def has_vertex_blocks(A: sp.csr_matrix, size: int = 3) -> bool:
    """Whether A's rows come in groups of ``size`` with one sparsity pattern each (the
    3D shells' vertex blocks) in nearly all of a few hundred groups spread over it (an
    entry that cancels to an exact zero drops out of a few)."""
    n = A.shape[0]
    if n % size or n < size:
        return False
    groups = np.unique(np.linspace(0, n // size - 1, min(256, n // size)).astype(int))
    agree = 0
    for group in groups:
        rows = [
            np.sort(A.indices[A.indptr[i] : A.indptr[i + 1]])
            for i in range(size * group, size * group + size)
        ]
        agree += all(np.array_equal(rows[0], r) for r in rows[1:])
    return agree >= 0.9 * groups.size


@contextmanager
def _one_mkl_thread(lib):
    """MKL on one thread in this thread for the duration (``mkl_set_num_threads_local``)."""
    previous = lib.MKL_Set_Num_Threads_Local(ctypes.c_int(1))
    try:
        yield
    finally:
        lib.MKL_Set_Num_Threads_Local(ctypes.c_int(previous))


class _Pardiso:
    """MKL PARDISO, real symmetric positive definite (mtype 2), upper triangle in CSR.
    The analysis (phase 11) tells the factor's in-core size (``in_core_mb``); above
    ``memory_budget_mb``, where out of core needs less, phase 22 writes it to a file."""

    MTYPE = 2  # a subclass may factor another type (benchmarks/sliced_solver.py: -2)

    def __init__(
        self,
        A: sp.csr_matrix,
        lib,
        memory_budget_mb: float | None = None,
        factorise=True,
    ):
        self._lib = lib
        U = sp.triu(A, format="csr")
        U.sum_duplicates()
        U.sort_indices()
        self.n = U.shape[0]
        self._ia = U.indptr.astype(np.int32)
        self._ja = U.indices.astype(np.int32)
        self._a = np.ascontiguousarray(U.data, dtype=np.float64)
        self._pt = np.zeros(64, dtype=np.int64)
        ip = np.zeros(64, dtype=np.int32)
        ip[0] = 1  # no solver defaults: the values below
        ip[1] = 3  # parallel nested dissection (METIS)
        ip[7] = 0  # no iterative refinement: the eigensolver checks its own residuals
        ip[23] = 1  # two-level parallel factorisation
        ip[24] = 1  # parallel forward/backward substitution
        ip[34] = 1  # zero-based indices
        if has_vertex_blocks(A):
            # variable-size block storage (VBSR) for the 3D shells' 3 x 3 vertex blocks:
            # a smaller factor made faster with the same residuals; a scalar operator's
            # factor grows with it, so scalar operators keep the plain storage
            ip[36] = -80
        self._iparm = ip
        self._alive = True
        self._folder: str | None = None
        self.out_of_core = False
        dummy = np.zeros((self.n, 1), dtype=np.float64, order="F")
        error, _ = self._call(11, dummy)
        if error != 0:
            self.release()
            raise np.linalg.LinAlgError(f"PARDISO analysis failed (error {error})")
        # iparm[15]: permanent symbolic data, iparm[16]: the factor, iparm[62]: the
        # smallest out-of-core buffer (KB)
        self.in_core_mb = (int(ip[15]) + int(ip[16])) / 1024.0
        self.factor_file_mb = int(ip[16]) / 1024.0
        minimum_mb = (int(ip[15]) + int(ip[62])) / 1024.0
        self.out_of_core_mb = OUT_OF_CORE_MARGIN * minimum_mb + OUT_OF_CORE_EXTRA_MB
        if not factorise:
            return
        if memory_budget_mb is not None and self.in_core_mb > max(
            memory_budget_mb, self.out_of_core_mb
        ):
            self._folder = self._out_of_core_folder()
        if self._folder is None:
            error, _ = self._call(22, dummy)
        else:
            self.out_of_core = True
            ip[59] = 2
            with _out_of_core_environment(self._folder, self.out_of_core_mb):
                error, _ = self._call(22, dummy)
            if error not in (0, -4):
                # out of core failed (buffer too small: -2, file errors: -10, -11): in
                # core it may still fit, and the caller must not read this as indefinite.
                # A fresh handle (so phase 12); the failed one is not released (PARDISO's
                # release can crash after error -2): its memory waits for the exit.
                self._pt = np.zeros(64, dtype=np.int64)
                ip[59] = 0
                self.out_of_core = False
                self._remove_folder()
                self._folder = None
                error, _ = self._call(12, dummy)
        if error != 0:
            self.release()
            if error == -4:
                raise np.linalg.LinAlgError("matrix is not positive definite")
            raise np.linalg.LinAlgError(f"PARDISO factorisation failed (error {error})")

    def _out_of_core_folder(self) -> str | None:
        """A new folder for the factor file, or None where it would not fit on the disk."""
        parent = factor_folder()
        remove_stale_factor_folders(parent)
        try:
            free_mb = shutil.disk_usage(parent).free / 2**20
            if free_mb < self.factor_file_mb + 1024:
                return None
            folder = tempfile.mkdtemp(prefix=f"{FOLDER_PREFIX}{os.getpid()}-", dir=parent)
        except OSError:
            return None
        # removed with the factor, or at the latest when the interpreter exits
        self._remove_folder = weakref.finalize(self, shutil.rmtree, folder, True)
        return folder

    def _call(self, phase: int, b: np.ndarray) -> tuple[int, np.ndarray]:
        """Run PARDISO ``phase`` on the Fortran-ordered (n, r) ``b``: (error code, x)."""
        i32 = ctypes.c_int32

        def ptr(a, t):
            return a.ctypes.data_as(ctypes.POINTER(t))

        x = np.zeros_like(b, order="F")
        err = i32(0)
        self._lib.pardiso(
            ptr(self._pt, ctypes.c_int64),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(self.MTYPE)),
            ctypes.byref(i32(phase)),
            ctypes.byref(i32(self.n)),
            ptr(self._a, ctypes.c_double),
            ptr(self._ia, i32),
            ptr(self._ja, i32),
            None,
            ctypes.byref(i32(b.shape[1])),
            ptr(self._iparm, i32),
            ctypes.byref(i32(0)),
            ptr(b, ctypes.c_double),
            ptr(x, ctypes.c_double),
            ctypes.byref(err),
        )
        return int(err.value), x

    def solve(self, b: np.ndarray) -> np.ndarray:
        one = b.ndim == 1
        B = np.asfortranarray(b.reshape(self.n, -1), dtype=np.float64)
        # out of core, PARDISO's parallel substitution reads the factor file many times
        # slower than one thread does (benchmarks/out_of_core_threads.py)
        with _one_mkl_thread(self._lib) if self.out_of_core else nullcontext():
            error, X = self._call(33, B)
        if error != 0:
            raise np.linalg.LinAlgError(f"PARDISO solve failed (error {error})")
        return X[:, 0].copy() if one else X

    def release(self) -> None:
        if self._alive:
            self._alive = False
            self._call(-1, np.zeros((self.n, 1), dtype=np.float64, order="F"))
        if self._folder is not None:
            self._remove_folder()
            self._folder = None

    def __del__(self):  # free MKL's memory for the factor
        try:
            self.release()
        except Exception:  # pragma: no cover - interpreter shutdown
            pass


class SPDSolver:
    """Factor a sparse symmetric positive definite matrix once, solve many times; a
    :class:`numpy.linalg.LinAlgError` if it is not positive definite.  ``out_of_core``:
    whether the factor lives in a file; ``factor_mb``: its in-core size (PARDISO only)."""

    out_of_core = False
    factor_mb: float | None = None

    def __init__(
        self,
        A: sp.spmatrix,
        backend: str = "auto",
        memory_budget_mb: float | None = None,
    ):
        A = sp.csr_matrix(A)
        names = available_backends()
        if backend == "auto":
            backend = names[0]
        elif backend not in ("pardiso", "cholmod", "superlu"):
            raise ValueError(f"unknown backend {backend!r}")
        elif backend not in names:
            raise ImportError(f"the {backend!r} backend is not available here")
        self.backend = backend
        if backend == "pardiso":
            self._impl = _Pardiso(A, _load_mkl(), memory_budget_mb)
            self.out_of_core = self._impl.out_of_core
            self.factor_mb = self._impl.in_core_mb
        elif backend == "cholmod":
            import cholespy

            coo = A.tocoo()
            try:
                self._chol = cholespy.CholeskySolverD(
                    A.shape[0],
                    coo.row.astype(np.int32),
                    coo.col.astype(np.int32),
                    np.ascontiguousarray(coo.data, dtype=np.float64),
                    cholespy.MatrixType.COO,
                )
            except ValueError as exc:
                raise np.linalg.LinAlgError(str(exc)) from None
        else:
            self._lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0)
            diag = self._lu.U.diagonal()
            if np.any(diag <= 0) or not np.all(np.isfinite(diag)):
                raise np.linalg.LinAlgError("matrix is not positive definite")

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve A x = b for b of shape (N,) or (N, r); returns the same shape."""
        if self.backend == "pardiso":
            return self._impl.solve(b)
        b = np.ascontiguousarray(b, dtype=np.float64)
        if self.backend == "cholmod":
            x = np.empty_like(b)
            self._chol.solve(b, x)
            return x
        return self._lu.solve(b)
