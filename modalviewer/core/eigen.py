"""Lowest eigenpairs of ``K phi = lambda M phi`` with a diagonal mass (shift-invert Lanczos).

The problem is solved in the standard form ``D^-1/2 K D^-1/2 y = lambda y`` (Vallet and
Levy 2008) with a shift ``sigma < 0`` below the spectrum, so the factored matrix
``K - sigma D`` is symmetric positive definite even when K is singular (constants,
rigid motions).  A sparse Cholesky factorisation (CHOLMOD through ``cholespy``, which
installs from wheels) is used where available, ``scipy.sparse.linalg.splu`` otherwise.
A final Rayleigh-Ritz step makes the modes Mass-orthonormal to machine precision and
the Ritz values the Rayleigh quotients.  Every run is deterministic (fixed start vector).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "Cancelled",
    "EigenError",
    "EigenResult",
    "SPDSolver",
    "solve_lowest",
    "relative_residuals",
    "ZERO_MODE_RTOL",
]

ZERO_MODE_RTOL = 1e-8
"""Eigenvalues below this times the largest computed one count as zero modes."""

DENSE_LIMIT = 1200
"""Problems with at most this many unknowns are solved densely (exact, fast)."""

REFINEMENT_STEPS = 1
"""Block shift-invert steps applied to the Lanczos basis before the Rayleigh-Ritz step."""

ProgressFn = Callable[[str, float], None]
CancelFn = Callable[[], bool]


class Cancelled(Exception):
    """Raised when the ``cancel`` callback asked to stop a computation."""


class EigenError(RuntimeError):
    """The eigensolver failed (no convergence, factorisation breakdown, bad residuals)."""


class SPDSolver:
    """Factor a sparse symmetric positive definite matrix once, solve many times.

    Uses CHOLMOD (``cholespy``) if importable, else SuperLU.  Raises
    :class:`numpy.linalg.LinAlgError` if the matrix is not positive definite.
    """

    def __init__(self, A: sp.spmatrix, backend: str = "auto"):
        A = sp.csr_matrix(A)
        self.n = A.shape[0]
        self.backend = backend
        if backend in ("auto", "cholmod"):
            try:
                import cholespy
            except ImportError:  # pragma: no cover - depends on the environment
                if backend == "cholmod":
                    raise
                self.backend = "superlu"
            else:
                self.backend = "cholmod"
                coo = A.tocoo()
                try:
                    self._chol = cholespy.CholeskySolverD(
                        self.n,
                        coo.row.astype(np.int32),
                        coo.col.astype(np.int32),
                        np.ascontiguousarray(coo.data, dtype=np.float64),
                        cholespy.MatrixType.COO,
                    )
                except ValueError as exc:
                    raise np.linalg.LinAlgError(str(exc)) from None
                return
        if self.backend != "superlu":
            raise ValueError(f"unknown backend {backend!r}")
        self._lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0)
        diag = self._lu.U.diagonal()
        if np.any(diag <= 0) or not np.all(np.isfinite(diag)):
            raise np.linalg.LinAlgError("matrix is not positive definite")

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve A x = b for b of shape (n,) or (n, r)."""
        b = np.ascontiguousarray(b, dtype=np.float64)
        if self.backend == "cholmod":
            x = np.empty_like(b)
            self._chol.solve(b, x)
            return x
        return self._lu.solve(b)


@dataclass
class EigenResult:
    eigenvalues: np.ndarray  # (k,) ascending
    vectors: np.ndarray  # (N, k), Mass-orthonormal
    residuals: np.ndarray  # (k,) relative residuals (absolute, scaled, for zero modes)
    shift: float
    method: str


def relative_residuals(
    K, mass_diag: np.ndarray, lam: np.ndarray, X: np.ndarray, lam_scale: float = 0.0
) -> np.ndarray:
    """|K x - lam M x| / |lam M x| per column; for zero modes |K x| / (lam_max |M x|).

    Zero modes are those below 1e-8 * max(largest |lam|, ``lam_scale``); ``lam_scale``
    (a typical eigenvalue size) keeps a spectrum of only zero modes from judging
    itself by its own rounding noise.
    """
    MX = mass_diag[:, None] * X
    R = K @ X - MX * lam[None, :]
    scale = np.abs(lam).copy()
    lam_max = max(float(np.abs(lam).max()), lam_scale, np.finfo(float).tiny)
    zero = scale < ZERO_MODE_RTOL * lam_max
    scale[zero] = lam_max
    return np.linalg.norm(R, axis=0) / (scale * np.linalg.norm(MX, axis=0))


def _fix_signs(X: np.ndarray) -> np.ndarray:
    """Deterministic sign: the entry of largest magnitude of each mode is positive."""
    idx = np.argmax(np.abs(X), axis=0)
    signs = np.sign(X[idx, np.arange(X.shape[1])])
    signs[signs == 0] = 1.0
    return X * signs


def _gershgorin_max(K: sp.csr_matrix, mass_diag: np.ndarray) -> float:
    row_abs = np.asarray(abs(K).sum(axis=1)).ravel()
    return float(np.max(row_abs / mass_diag))


def solve_lowest(
    K: sp.spmatrix,
    mass_diag: np.ndarray,
    k: int,
    *,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    dense_limit: int = DENSE_LIMIT,
    tol: float = 1e-12,
) -> EigenResult:
    """The k lowest eigenpairs of ``K x = lam diag(mass_diag) x``.

    Parameters
    ----------
    K : (N, N) symmetric positive semi-definite sparse matrix.
    mass_diag : (N,) positive masses.
    k : number of eigenpairs, 1 <= k <= N.
    progress : called as ``progress(stage, fraction)``.
    cancel : polled during the solve; returning True raises :class:`Cancelled`.

    Returns
    -------
    EigenResult with ascending eigenvalues and Mass-orthonormal vectors.
    """
    K = sp.csr_matrix(K)
    N = K.shape[0]
    mass_diag = np.asarray(mass_diag, dtype=np.float64)
    if not (1 <= k <= N):
        raise ValueError(f"k must be between 1 and {N} (the number of unknowns), got {k}")
    if np.any(mass_diag <= 0) or not np.all(np.isfinite(mass_diag)):
        raise EigenError("the mass matrix has non-positive entries (degenerate faces?)")
    if not np.all(np.isfinite(K.data)):
        raise EigenError("the operator has NaN or infinite entries")

    def report(stage: str, fraction: float) -> None:
        if cancel is not None and cancel():
            raise Cancelled()
        if progress is not None:
            progress(stage, float(min(max(fraction, 0.0), 1.0)))

    inv_sqrt_m = 1.0 / np.sqrt(mass_diag)
    lam_max_est = _gershgorin_max(K, mass_diag)

    if N <= dense_limit:
        report("solving (dense)", 0.1)
        lam, X = la.eigh(K.toarray(), np.diag(mass_diag), subset_by_index=[0, k - 1])
        method, shift = "dense", 0.0
    else:
        lam_typical = float(np.median(np.abs(K.diagonal()) / mass_diag)) or lam_max_est
        lam, X, shift = _shift_invert(K, mass_diag, inv_sqrt_m, k, lam_typical, report, tol)
        method = "shift-invert lanczos"
    report("checking residuals", 0.97)
    X = _fix_signs(X)
    lam_typical = float(np.median(np.abs(K.diagonal()) / mass_diag))
    res = relative_residuals(K, mass_diag, lam, X, lam_scale=lam_typical)
    if not np.all(np.isfinite(lam)) or not np.all(np.isfinite(X)):
        raise EigenError("the eigensolver produced NaN values")
    return EigenResult(lam, X, res, shift, method)


def _shift_invert(K, mass_diag, inv_sqrt_m, k, lam_typical, report, tol):
    N = K.shape[0]
    sqrt_m = np.sqrt(mass_diag)
    # Far below the first non-zero mode, yet factorisable.  Scaled by the typical diagonal
    # ratio, not the largest: one sliver triangle can make the largest 1e12 times bigger.
    shift = -1e-8 * lam_typical
    solver = None
    for _ in range(4):
        report("factorising", 0.05)
        try:
            solver = SPDSolver(K - shift * sp.diags(mass_diag))
            break
        except np.linalg.LinAlgError:
            shift *= 100.0  # move further below the spectrum and try again
    if solver is None:
        raise EigenError(
            "the operator could not be factorised even with a shift below zero; "
            "it is probably not positive semi-definite (check the mesh for degenerate faces)"
        )
    # Ask for a few more pairs than needed: single-vector Lanczos can miss a copy of a
    # multiple eigenvalue (symmetric shapes), which the extra pairs then supply.
    k_wanted = k
    k = min(N - 1, k + max(8, k // 10))
    ncv = min(N, max(2 * k + 1, k + 32))
    calls = [0]
    expected = 3.0 * ncv

    def op_inv(y: np.ndarray) -> np.ndarray:
        calls[0] += 1
        if calls[0] % 8 == 0:
            report("solving", 0.1 + 0.85 * (1.0 - np.exp(-calls[0] / expected)))
        return (
            sqrt_m * solver.solve(sqrt_m * y)
            if y.ndim == 1
            else (sqrt_m[:, None] * solver.solve(sqrt_m[:, None] * y))
        )

    def c_matvec(y: np.ndarray) -> np.ndarray:
        return inv_sqrt_m * (K @ (inv_sqrt_m * y))

    C = spla.LinearOperator((N, N), matvec=c_matvec, dtype=np.float64)
    OP = spla.LinearOperator((N, N), matvec=op_inv, dtype=np.float64)
    v0 = np.random.default_rng(12345).standard_normal(N)
    report("solving", 0.1)
    try:
        _, Y = spla.eigsh(C, k=k, sigma=shift, which="LM", OPinv=OP, v0=v0, ncv=ncv, tol=tol)
    except spla.ArpackNoConvergence:
        try:
            ncv2 = min(N, 2 * ncv)
            _, Y = spla.eigsh(C, k=k, sigma=shift, which="LM", OPinv=OP, v0=v0, ncv=ncv2, tol=tol)
        except spla.ArpackNoConvergence as exc:
            raise EigenError(
                f"the eigensolver did not converge ({len(exc.eigenvalues)} of {k} modes); "
                "try fewer modes"
            ) from None
    # Rayleigh-Ritz in the computed subspace: orthonormal basis, exact Ritz values.
    # One block shift-invert step on the whole subspace before Rayleigh-Ritz: damps the
    # remaining high-frequency error of every Ritz vector by (lam_j - s)/(lam_k+1 - s).
    report("refining", 0.93)
    for _ in range(REFINEMENT_STEPS):
        Q, _ = np.linalg.qr(Y)
        Y = sqrt_m[:, None] * solver.solve(sqrt_m[:, None] * Q)
    report("orthonormalising", 0.95)
    Q, _ = np.linalg.qr(Y)
    T = Q.T @ (inv_sqrt_m[:, None] * (K @ (inv_sqrt_m[:, None] * Q)))
    lam, W = np.linalg.eigh(0.5 * (T + T.T))
    Y = Q @ W[:, :k_wanted]
    X = inv_sqrt_m[:, None] * Y
    return lam[:k_wanted], X, shift
