"""Lowest eigenpairs of ``K phi = lambda M phi`` with a diagonal mass.

Solved in the standard form ``C = M^-1/2 K M^-1/2`` (Vallet and Levy 2008) by
shift-invert: the largest ``theta = 1 / (lambda - shift)`` of
``OP = M^1/2 (K - shift M)^-1 M^1/2``, with a shift below zero so the factored matrix is
positive definite even when K is singular.  The factorisation is :mod:`.factor`'s; the
iteration is block Krylov-Schur (:func:`.krylov.block_krylov_schur`), so one pass over
the factor serves a block of right-hand sides, with a few more pairs than wanted
(:func:`.memory.krylov_sizes`).  A block step of inverse iteration and a Rayleigh-Ritz
step with K give Mass-orthonormal modes and residuals
``|K x - lambda M x| / |lambda M x|`` near 1e-10 on well-shaped meshes.  Within the
memory limit (:mod:`.memory`) the factor goes out of core where it would not fit beside
the Krylov basis (:func:`.memory.factor_budget_mb`), and the modes are written over the
basis.  Every run is deterministic (fixed start block) and reports its residuals;
docs/how-it-works.md, "How the eigenproblems are solved", gives the reasons.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

from .factor import SPDSolver
from .krylov import (
    ConvergedFn,
    EigenError,
    NotConverged,
    ProgressFn,
    StageTimer,
    block_krylov_schur,
    cholqr_in_place,
    rotate_in_place,
)
from .memory import basis_in_float32, factor_budget_mb, float32_basis_mb, krylov_sizes
from .memory import memory_limit_mb as default_memory_limit_mb
from .products import (
    column_block_products,
    column_norms,
    move_columns_in_place,
    single_blas_thread,
    threaded_product,
)

ZERO_MODE_RTOL = 1e-8
"""Eigenvalues below this times the largest computed one count as zero modes."""
ZERO_NOISE_RTOL = 1e-12
"""Eigenvalues below this times the typical eigenvalue size (median diag(K) / mass) are
zero modes whatever else was computed: above the rounding noise of undeflated null
vectors, below the first bending vibrations of fine meshes, which fall like h^4 ("Zero
modes, one rule" in docs/how-it-works.md)."""

DENSE_LIMIT = 1200
"""Problems with at most this many unknowns are solved densely (exact, fast)."""

SHIFT_RTOL = 1e-6
"""The shift is ``-SHIFT_RTOL * median(diag(K) / mass)`` when K's null space is not
deflated: far enough below zero that rounding in the solves cannot blow up the null
vectors' components (OP multiplies them by 1 / |shift|)."""
DEFLATED_SHIFT_RTOL = 1e-10
"""The shift's relative size when the exactly known null vectors are deflated (every
solve is projected, so their amplification does no harm); small against the first
non-zero eigenvalue, since the median diagonal ratio grows like 1/h^4 for bending
energies ("Known null spaces" in docs/how-it-works.md)."""

CancelFn = Callable[[], bool]


class Cancelled(Exception):
    """Raised when the ``cancel`` callback asked to stop a computation."""


@dataclass
class EigenResult:
    eigenvalues: np.ndarray  # (k,) ascending
    vectors: np.ndarray  # (N, k), Mass-orthonormal
    residuals: np.ndarray  # (k,) relative residuals (absolute, scaled, for zero modes)
    shift: float
    method: str
    # seconds per stage: "factorisation", "solves" (the Krylov iteration's),
    # "orthogonalisation", "ritz" (projected eigenproblems), "restarts" (basis rotations),
    # "refinement" (the last block of solves), "rayleigh_ritz" (with K itself),
    # "residuals", "copy" (into the row-major result; a single-precision basis widened
    # into the modes), "dense"
    stage_seconds: dict[str, float] = field(default_factory=dict)
    operator_columns: int = 0  # shift-invert operator applications, refinement included
    null_dim: int = 0  # the first null_dim pairs are the given exact null vectors (lam 0)
    factor_mb: float | None = None  # the factor's in-core size (PARDISO's analysis)
    # the factor did not fit the memory limit beside the Krylov basis: kept in a file
    out_of_core: bool = False
    # even with the factor out of core a double-precision Krylov basis would not fit the
    # memory limit (:func:`.memory.basis_in_float32`): it was stored in single precision
    basis_float32: bool = False


def zero_modes(lam: np.ndarray, lam_scale: float = 0.0, null_dim: int = 0) -> np.ndarray:
    """Boolean mask (k,) of the zero modes, the one rule for masks, signatures and
    residual checks: the first ``null_dim`` modes (the deflated null vectors), and any
    mode with ``lam < ZERO_MODE_RTOL * largest |lam|`` or ``lam < ZERO_NOISE_RTOL *
    lam_scale`` (:func:`typical_eigenvalue`, so a spectrum of only undeflated zero modes
    is not judged by its own rounding noise)."""
    lam = np.asarray(lam, dtype=np.float64)
    largest = max(float(np.abs(lam).max(initial=0.0)), np.finfo(float).tiny)
    mask = (lam < ZERO_MODE_RTOL * largest) | (lam < ZERO_NOISE_RTOL * lam_scale)
    mask[: max(0, int(null_dim))] = True
    return mask


def typical_eigenvalue(K, mass_diag: np.ndarray) -> float:
    """median(diag(K) / mass): the eigenvalue size zero modes are judged against when a
    spectrum holds nothing larger (``lam_scale`` of :func:`zero_modes`)."""
    return float(np.median(np.abs(K.diagonal()) / np.asarray(mass_diag)))


def zero_mode_size(lam: np.ndarray, lam_scale: float) -> float:
    """The eigenvalue size zero modes are judged against (a zero mode has no size of its
    own): max(largest |lam|, lam_scale)."""
    return max(float(np.abs(lam).max(initial=0.0)), lam_scale, np.finfo(float).tiny)


def relative_residuals(
    K, mass_diag: np.ndarray, lam: np.ndarray, X: np.ndarray, lam_scale: float = 0.0
) -> np.ndarray:
    """|K x - lam M x| / |lam M x| per column; |K x| / (lam_max |M x|) for the zero modes
    of :func:`zero_modes` (``lam_scale`` is passed on; the exact null vectors have their
    own residuals, :func:`_null_residuals`)."""
    scale = np.abs(lam).copy()
    scale[zero_modes(lam, lam_scale)] = zero_mode_size(lam, lam_scale)
    out = np.empty(X.shape[1])
    for cols, KX in column_block_products(K, X):  # (N, 32) temporaries, not three (N, k) ones
        MX = mass_diag[:, None] * X[:, cols]
        R = KX - MX * lam[None, cols]
        out[cols] = np.linalg.norm(R, axis=0) / (scale[cols] * np.linalg.norm(MX, axis=0))
    return out


def rounding_floors(
    K, mass_diag: np.ndarray, lam: np.ndarray, X: np.ndarray, columns=None
) -> np.ndarray:
    """``eps * | |K| |x| | / (|lam| |M x|)`` per column: the relative residual that merely
    rounding x to double precision can cause, which no solver can go below (large on
    fine meshes with a wide spread of stiffness).  ``columns``: the columns of X to look
    at (``lam`` their eigenvalues; None: all), taken 32 at a time to avoid (N, k)
    copies."""
    K_abs = abs(sp.csr_matrix(K))
    columns = np.arange(X.shape[1]) if columns is None else np.asarray(columns, dtype=np.intp)
    out = np.empty(columns.shape[0])
    for start in range(0, columns.shape[0], 32):
        chosen = columns[start : start + 32]
        block = X[:, chosen]  # (N, 32)
        MX = mass_diag[:, None] * block
        np.abs(block, out=block)
        KX = threaded_product(K_abs, block)
        out[start : start + 32] = np.linalg.norm(KX, axis=0) / np.linalg.norm(MX, axis=0)
    return np.finfo(float).eps * out / np.maximum(np.abs(lam), np.finfo(float).tiny)


def _fix_signs(X: np.ndarray, rows: int = 2048) -> np.ndarray:
    """Deterministic sign: the entry of largest magnitude of each mode is positive
    (changes and returns X).  Blocks of rows: X may be a row-major (N, k) view, where
    a column-wise argmax over the whole array is three times slower."""
    k = X.shape[1]
    largest = np.full(k, -1.0)
    signs = np.ones(k)
    columns = np.arange(k)
    for start in range(0, X.shape[0], rows):
        part = X[start : start + rows]
        values = part[np.abs(part).argmax(axis=0), columns]
        better = np.abs(values) > largest
        largest[better] = np.abs(values[better])
        signs[better] = np.where(values[better] < 0, -1.0, 1.0)
    X *= signs  # in place: X is up to 1 GB
    return X


@single_blas_thread
def solve_lowest(
    K: sp.spmatrix,
    mass_diag: np.ndarray,
    k: int,
    *,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    dense_limit: int = DENSE_LIMIT,
    tol: float = 1e-10,
    block: int | None = None,
    null_space: sp.spmatrix | np.ndarray | None = None,
    memory_limit_mb: float | None = None,
    on_modes: ConvergedFn | None = None,
) -> EigenResult:
    """The k lowest eigenpairs (1 <= k <= N) of ``K x = lam diag(mass_diag) x``, K
    symmetric positive semi-definite: eigenvalues ascending, vectors Mass-orthonormal.

    ``cancel`` is polled; returning True raises :class:`Cancelled`.  ``null_space``: (N, d)
    exact Mass-orthonormal null vectors of K (:func:`.nullspace.null_space`), returned
    first as eigenvalue 0 and counted in k; the iteration works in their Mass-orthogonal
    complement, so it neither returns them again nor misses any (with d >= k no
    factorisation is made).  ``memory_limit_mb`` (None: :func:`.memory.memory_limit_mb`):
    beyond it the factor goes out of core, and then the basis to single precision
    (:func:`.memory.basis_in_float32`).  ``on_modes(eigenvalues, vectors)`` receives the
    pairs as they converge, lowest first, (m,) eigenvalues and a new (N, m) array, the
    null vectors first, equal to the result's to the solver's tolerance; the dense solver
    does not call it, nor is it called where the null vectors fill all k.
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
    report = progress_reporter(progress, cancel)
    median_ratio = typical_eigenvalue(K, mass_diag)
    Z = sp.csc_matrix((N, 0) if null_space is None else null_space, dtype=np.float64)
    d = Z.shape[1]
    if Z.shape[0] != N:
        raise ValueError(f"null_space must have {N} rows (the unknowns), got {Z.shape[0]}")
    if d and np.abs((Z.T @ sp.diags(mass_diag) @ Z).toarray() - np.eye(d)).max() > 1e-8:
        raise ValueError("null_space must be Mass-orthonormal (Z^T M Z = I)")
    Zk = _fix_column_signs(Z[:, : min(d, k)])  # the first modes, signs as the others'
    timer = StageTimer()
    columns = 0
    method, shift = "null space (no iteration)", 0.0
    lam, X = np.zeros(0), np.zeros((N, 0))
    basis = None  # the Krylov basis array whose first columns hold the modes
    solver_info = {"factor_mb": None, "out_of_core": False, "basis_float32": False}
    if d < k:
        limit = default_memory_limit_mb() if memory_limit_mb is None else float(memory_limit_mb)
        lam, X, basis, shift, method, columns = _complement_pairs(
            K, mass_diag, Z, k, median_ratio, report, timer, dense_limit, tol, block, limit,
            solver_info, _Handover(on_modes, Zk),
        )  # fmt: skip
    all_lam = np.concatenate([np.zeros(min(d, k)), lam])
    report("checking residuals", 0.97)
    with timer("residuals"):
        X = _fix_signs(X)
        res_rest = relative_residuals(K, mass_diag, lam, X, lam_scale=median_ratio)
        res_null = _null_residuals(K, mass_diag, Zk, zero_mode_size(all_lam, median_ratio))
    if not np.all(np.isfinite(lam)) or not np.all(np.isfinite(X)):
        raise EigenError("the eigensolver produced NaN values")
    with timer("copy"):  # own row-major array ((n, 3, k) shells modes are then a view)
        d_out = Zk.shape[1]
        if basis is not None and basis.shape[1] >= k:
            # written over the Krylov basis, which is then shrunk to the modes: no (N, k)
            # array beside the (N, 1.1 k + extra) basis, the largest arrays of a big solve
            del X
            move_columns_in_place(basis, lam.shape[0], lead=d_out)  # view not kept
            try:
                basis.resize((N, k))  # refuses while another reference to it is alive
                out = basis
            except ValueError:
                out = basis.reshape(-1)[: N * k].reshape(N, k).copy()
        else:  # no basis, or more null vectors than the basis has columns
            out = np.empty((N, k))
            out[:, d_out:] = X
            del X
        basis = None
        out[:, :d_out] = 0.0
        coo = Zk.tocoo()
        out[coo.row, coo.col] = coo.data
    res = np.concatenate([res_null, res_rest])
    return EigenResult(
        all_lam, out, res, shift, method, timer.seconds, columns, Zk.shape[1], **solver_info
    )


def progress_reporter(progress: ProgressFn | None, cancel: CancelFn | None) -> ProgressFn:
    """``report(stage, fraction)``: raises :class:`Cancelled` when ``cancel`` asks to
    stop, else passes the fraction, clipped to [0, 1], to ``progress``."""

    def report(stage: str, fraction: float) -> None:
        if cancel is not None and cancel():
            raise Cancelled()
        if progress is not None:
            progress(stage, float(min(max(fraction, 0.0), 1.0)))

    return report


def _complement_pairs(
    K, mass_diag, Z, k, median_ratio, report, timer, dense_limit, tol, block, limit,
    solver_info, handover,
):  # fmt: skip
    """The k - d lowest pairs in the Mass-orthogonal complement of the d null vectors
    Z: by shift-invert where the problem is large enough, densely otherwise.  Returns
    (eigenvalues, vectors, the Krylov basis array whose first columns are the vectors or
    None, shift, method, operator columns)."""
    N, d = K.shape[0], Z.shape[1]
    # the standard-form null vectors M^1/2 Z are orthonormal: project them out
    Y0 = sp.csr_matrix(sp.diags(np.sqrt(mass_diag)) @ Z)
    Y0t = sp.csr_matrix(Y0.T)

    def project(V: np.ndarray) -> np.ndarray:
        if d:
            V -= Y0 @ (Y0t @ V)
        return V

    deflated = f", {d} null vectors deflated" if d else ""
    # A few more pairs than requested: the last requested pairs then converge as fast as
    # the others (the gap to the unwanted part of the spectrum is larger).
    sizes = krylov_sizes(k - d, N - d, block)  # working pairs, block, basis, kept
    if N - d > dense_limit and sizes[2] + sizes[1] <= N - d:  # else the basis does not fit
        # median_ratio is 0 where half of K's diagonal is: then Gershgorin's bound
        lam_typical = median_ratio or float(
            np.max(np.asarray(abs(K).sum(axis=1)).ravel() / mass_diag)
        )
        args = (K, mass_diag, 1.0 / np.sqrt(mass_diag), k - d, lam_typical, report, tol, sizes,
                timer, project, limit, solver_info, k)  # fmt: skip

        def attempt(shift_rtol: float):
            return _shift_invert(*args, shift_rtol, handover.attempt())

        try:
            lam, basis, shift, backend, columns = attempt(DEFLATED_SHIFT_RTOL if d else SHIFT_RTOL)
        except NotConverged as failed:
            # the tiny deflated shift leaves K - shift M so close to singular that the
            # solves' rounding floor can sit above the tolerance (residuals stuck near
            # 1e-8): again with the larger SHIFT_RTOL, at the cost of a compressed spectrum
            if not d:
                raise
            report("retrying with a larger shift", 0.05)
            lam, basis, shift, backend, columns = attempt(SHIFT_RTOL)
            columns += failed.columns  # the failed attempt's count too
        method = f"shift-invert block Krylov-Schur ({backend})"
        if solver_info["out_of_core"]:
            method += ", factor out of core"
        if solver_info["basis_float32"]:
            method += ", single-precision Krylov basis"
        return lam, basis[:, : lam.shape[0]], basis, shift, method + deflated, columns
    report("solving (dense)", 0.1)
    with timer("dense"):
        lam, X = _dense_complement(K, mass_diag, Y0, k - d)
    return lam, X, None, 0.0, "dense" + deflated, 0


class _Handover:
    """Relays converged pairs to ``solve_lowest``'s ``on_modes``: the null vectors
    first, then the iteration's pairs, each once (a retried iteration hands over its
    first pairs again: those already relayed are skipped), signs fixed as in the
    result."""

    def __init__(self, on_modes: ConvergedFn | None, Zk: sp.csc_matrix) -> None:
        self.on_modes = on_modes
        self.Zk = Zk  # the null vectors among the first k modes
        self.relayed = 0  # iteration pairs relayed
        self.seen = 0  # pairs the current attempt has handed over

    def attempt(self) -> ConvergedFn | None:
        """The callback for one attempt of the iteration (None without ``on_modes``)."""
        self.seen = 0
        return None if self.on_modes is None else self._relay

    def _relay(self, lam: np.ndarray, X: np.ndarray) -> None:
        skip = max(0, self.relayed - self.seen)
        self.seen += lam.shape[0]
        lam, X = lam[skip:], _fix_signs(X[:, skip:])
        if lam.shape[0] == 0:
            return
        first = self.relayed == 0
        self.relayed += lam.shape[0]
        if first and self.Zk.shape[1]:
            lam = np.concatenate([np.zeros(self.Zk.shape[1]), lam])
            X = np.hstack([self.Zk.toarray(), X])
        self.on_modes(lam, X)


def _fix_column_signs(Z: sp.csc_matrix) -> sp.csc_matrix:
    """Sparse columns with their entry of largest magnitude positive (as _fix_signs)."""
    Z = sp.csc_matrix(Z, copy=True)
    for j in range(Z.shape[1]):
        data = Z.data[Z.indptr[j] : Z.indptr[j + 1]]
        if data.size and data[np.abs(data).argmax()] < 0:
            data *= -1.0
    return Z


def _null_residuals(K, mass_diag, Z: sp.csc_matrix, lam_max: float) -> np.ndarray:
    """|K z| / (lam_max |M z|) per column of the sparse null vectors (none: empty)."""
    KZ = sp.csc_matrix(K @ Z)
    MZ = sp.csc_matrix(sp.diags(mass_diag) @ Z)
    return column_norms(KZ) / (lam_max * column_norms(MZ))


def _dense_complement(K, mass_diag, Y0: sp.csr_matrix, k: int):
    """Lowest k pairs of the standard form restricted to the orthogonal complement of
    the orthonormal columns Y0 (dense; small problems)."""
    if Y0.shape[1] == 0:
        return la.eigh(K.toarray(), np.diag(mass_diag), subset_by_index=[0, k - 1])
    inv_sqrt_m = 1.0 / np.sqrt(mass_diag)
    C = inv_sqrt_m[:, None] * K.toarray() * inv_sqrt_m[None, :]
    Q = la.qr(Y0.toarray(), mode="full")[0][:, Y0.shape[1] :]
    CQ = C @ Q
    lam, W = la.eigh(0.5 * (Q.T @ CQ + CQ.T @ Q), subset_by_index=[0, k - 1])
    return lam, inv_sqrt_m[:, None] * (Q @ W)


def factor_below_spectrum(
    K,
    mass_diag,
    lam_typical,
    report,
    timer,
    relative: float = SHIFT_RTOL,
    memory_budget_mb: float | None = None,
) -> tuple[SPDSolver, float]:
    """Factor ``K - shift * M`` with ``shift = -relative * lam_typical`` just below zero
    (K may be singular), moving further down while the factorisation fails.
    ``memory_budget_mb``: the memory the factor may take in core (:class:`.SPDSolver`)."""
    # Far below the first non-zero mode, yet factorisable.  Scaled by the typical diagonal
    # ratio, not the largest: one sliver triangle can make the largest 1e12 times bigger.
    shift = -relative * lam_typical
    for _ in range(1 + round(np.log(1.0 / relative) / np.log(100.0))):  # up to -lam_typical
        report("factorising", 0.02)
        try:
            with timer("factorisation"):
                shifted = K - shift * sp.diags(mass_diag)
                return SPDSolver(shifted, memory_budget_mb=memory_budget_mb), shift
        except np.linalg.LinAlgError:
            shift *= 100.0  # move further below the spectrum and try again
    raise EigenError(
        "the operator could not be factorised even with a shift below zero: it is "
        "numerically indefinite; if the mesh has nearly degenerate (sliver) triangles, "
        "modalviewer.fix_slivers(mesh) removes them (in the viewer: Mesh > Fix slivers)"
    )


FLOAT32_BASIS_TOL = 1e-7
"""Convergence tolerance of the Krylov iteration with a single-precision basis (its
columns are orthonormal to about that); the final inverse iteration and Rayleigh-Ritz
in double precision bring the residuals to what a double-precision basis gives."""


def _widen_in_place(buffer: np.ndarray, n: int, width: int, count: int, out_width: int):
    """Rewrite the first ``count`` columns of the C-order (n, width) float32 array at the
    start of ``buffer`` (1-D float64) as float64 columns of the C-order (n, out_width)
    array at its start; the other columns are left undefined.  The rows are taken a
    block at a time, backwards where the new rows are longer (a row's new place then
    lies after its old one), forwards where they are shorter, each block copied before
    it is written: no (n, count) temporary."""
    single = buffer.view(np.float32)[: n * width].reshape(n, width)
    double = buffer[: n * out_width].reshape(n, out_width)
    rows = 4096
    starts = range(0, n, rows)
    for start in reversed(starts) if 8 * out_width > 4 * width else starts:
        block = single[start : start + rows, :count].astype(np.float64)
        double[start : start + rows, :count] = block


def _shift_invert(
    K, mass_diag, inv_sqrt_m, k, lam_typical, report, tol, sizes, timer, project, limit_mb,
    solver_info, out_columns, shift_rtol, on_converged=None,
):  # fmt: skip
    """Lowest k pairs by block Krylov-Schur on ``M^1/2 (K - shift M)^-1 M^1/2`` in the
    complement of the deflated null vectors that ``project`` removes, with the
    :func:`.memory.krylov_sizes` ``sizes``: (eigenvalues, (N, w) array whose first k
    columns are the Mass-orthonormal modes, shift, backend name, operator columns).  The
    factor and basis keep within ``limit_mb`` (:func:`.memory.factor_budget_mb`,
    :func:`.memory.basis_in_float32`; with a single-precision basis w is exactly
    ``out_columns``); ``solver_info`` receives "factor_mb", "out_of_core" and
    "basis_float32"; ``on_converged`` the pairs of K as they converge."""
    N = K.shape[0]
    sqrt_m = np.sqrt(mass_diag)
    _, block, max_basis, keep = sizes
    budget = factor_budget_mb(limit_mb, N, max_basis + block, block)
    solver, shift = factor_below_spectrum(
        K, mass_diag, lam_typical, report, timer, shift_rtol, budget
    )
    width = max_basis + block
    float32 = basis_in_float32(limit_mb, N, width, out_columns, block)
    solver_info.update(
        factor_mb=solver.factor_mb, out_of_core=solver.out_of_core, basis_float32=float32
    )
    buffer = Q = None
    if float32:
        # one buffer for the single-precision basis and, later, the double-precision modes
        buffer = np.empty(int(np.ceil(float32_basis_mb(N, width, out_columns) * 2**20 / 8)))
        Q = buffer.view(np.float32)[: N * width].reshape(N, width)
        tol = max(tol, FLOAT32_BASIS_TOL)

    def apply_op(V: np.ndarray) -> np.ndarray:
        # the null vectors are an invariant subspace of OP, with its largest eigenvalue
        # 1 / |shift|: rounding brings them back in every solve, so each result is projected
        return project(sqrt_m[:, None] * solver.solve(sqrt_m[:, None] * V))

    def relay(theta: np.ndarray, Y: np.ndarray) -> None:
        Y *= inv_sqrt_m[:, None]  # in place: standard-form vectors to K's
        on_converged(shift + 1.0 / theta, Y)

    # At a restart the basis keeps the working pairs and the best third of the unwanted
    # Ritz vectors next to them, which carry the part of the spectrum the last wanted
    # pairs must be told apart from: fewer operator columns than keeping only the
    # working pairs.
    theta, Y, columns = block_krylov_schur(
        apply_op,
        N,
        k,
        keep=keep,
        block=block,
        max_basis=max_basis,
        tol=tol,
        report=report,
        timer=timer,
        project=project,
        basis=Q,
        on_converged=None if on_converged is None else relay,
    )
    if float32:
        with timer("copy"):
            del Y, Q  # views of the buffer: it is resized below
            _widen_in_place(buffer, N, width, theta.shape[0], out_columns)
            buffer.resize((N, out_columns))
            Y = buffer[:, : theta.shape[0]]
    # One block step of inverse iteration on the converged subspace, then Rayleigh-Ritz
    # with K itself: K amplifies the Gram-Schmidt rounding noise by its largest
    # eigenvalue, and one application of OP damps it by the same factor.
    report("refining", 0.9)
    step = 2 * block  # each step has four (N, step) temporaries
    for start in range(0, Y.shape[1], step):
        with timer("refinement"):
            Y[:, start : start + step] = apply_op(Y[:, start : start + step])
        report("refining", 0.9 + 0.05 * start / Y.shape[1])
    columns += Y.shape[1]
    backend = solver.backend
    solver = None  # free the factor (apply_op's closure holds it) before the last step
    # Everything below works in place on Y, a view into the Krylov basis, or on (N, 32)
    # pieces: an (N, k) temporary would be as large as the modes.
    report("orthonormalising", 0.95)
    with timer("rayleigh_ritz"):
        lam = _rayleigh_ritz_in_place(K, inv_sqrt_m, Y)
    basis = Y.base
    return lam, basis, shift, backend, columns


GRAM_CONDITION_LIMIT = 1e4
"""Largest condition number of the scaled Gram matrix for which the final Rayleigh-Ritz
step works in the given basis (M-orthonormality then holds to about 1e-16 times this);
beyond it the basis is orthonormalised first."""


def _rayleigh_ritz_in_place(K, inv_sqrt_m: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Rayleigh-Ritz with K on the span of Y, in place: ascending Ritz values (k,); Y
    (N, k), standard-form vectors (``x = M^-1/2 y``), becomes the Mass-orthonormal Ritz
    vectors.  After inverse iteration, Y's unit-scaled columns have a Gram matrix B near
    the identity, so ``G w = lam B w`` replaces orthonormalising Y (one product over Y
    instead of four)."""
    B = Y.T @ Y
    d = 1.0 / np.sqrt(np.diag(B))
    B = d[:, None] * B * d[None, :]
    gram_eigenvalues = np.linalg.eigvalsh(B)
    if not gram_eigenvalues[0] * GRAM_CONDITION_LIMIT > gram_eigenvalues[-1]:
        if not cholqr_in_place(Y):
            Y[:] = np.linalg.qr(Y)[0]
        B, d = np.eye(Y.shape[1]), np.ones(Y.shape[1])
    Y *= inv_sqrt_m[:, None]
    G = np.empty_like(B)
    for cols, KY in column_block_products(K, Y):  # (N, 32) temporaries
        G[:, cols] = Y.T @ KY
    G = d[:, None] * G * d[None, :]
    lam, W = la.eigh(0.5 * (G + G.T), 0.5 * (B + B.T))
    rotate_in_place(Y, Y.shape[1], d[:, None] * W)
    return lam
