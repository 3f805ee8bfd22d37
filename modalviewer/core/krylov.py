"""Block Krylov-Schur (thick-restart block Lanczos) for the largest eigenpairs of a
symmetric positive definite operator, with full re-orthogonalisation in BLAS-3 blocks
and the hand-over of converged pairs while it runs.  :func:`.eigen.solve_lowest` applies
it to the shift-invert operator."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

import numpy as np
import scipy.linalg as la

ProgressFn = Callable[[str, float], None]
ConvergedFn = Callable[[np.ndarray, np.ndarray], None]
"""``on_converged(values, vectors)``: newly converged pairs, handed over in order."""


class EigenError(RuntimeError):
    """The eigensolver failed (no convergence, factorisation breakdown, bad residuals)."""


class NotConverged(EigenError):
    """The Krylov iteration ran out of restarts (the solver may retry differently);
    ``columns``: the operator columns it applied before giving up."""

    def __init__(self, message: str, columns: int = 0) -> None:
        super().__init__(message)
        self.columns = columns


class StageTimer:
    """Wall-clock seconds per stage of a solve, accumulated over calls."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    @contextmanager
    def __call__(self, stage: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[stage] = self.seconds.get(stage, 0.0) + (time.perf_counter() - start)


def _gram_cholesky(W: np.ndarray) -> np.ndarray | None:
    """Upper Cholesky factor C of ``W.T @ W`` (so ``W @ inv(C)`` has orthonormal columns),
    or None if W is numerically rank deficient (C's diagonal spans more than 1e7)."""
    G = W.T @ W
    try:
        C = la.cholesky(0.5 * (G + G.T), lower=False)
    except la.LinAlgError:
        return None
    d = np.abs(np.diag(C))
    return None if d.min() <= 1e-7 * d.max() else C


def _cholqr(W: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """W = V Rn with orthonormal V by two Cholesky-QR passes (BLAS-3), or None if W is
    numerically rank deficient (then Householder QR takes over)."""
    Rn = np.eye(W.shape[1])
    for _ in range(2):
        C = _gram_cholesky(W)
        if C is None:
            return None
        W = W @ la.solve_triangular(C, np.eye(W.shape[1]), lower=False)
        Rn = C @ Rn
    return W, Rn


def cholqr_in_place(Y: np.ndarray) -> bool:
    """Orthonormalise the columns of Y in place by two Cholesky-QR passes (BLAS-3, no
    (N, k) temporary); False if Y is numerically rank deficient (Y then still spans
    the same space, and Householder QR takes over)."""
    for _ in range(2):
        C = _gram_cholesky(Y)
        if C is None:
            return False
        rotate_in_place(Y, Y.shape[1], la.solve_triangular(C, np.eye(Y.shape[1])))
    return True


_SWEEP_ROWS = 1024
"""Rows of the basis per step of the fused orthogonalisation sweep: a block of rows of
a basis of a few hundred columns stays inside the L3 cache."""


def _basis_t_times(Q: np.ndarray, W: np.ndarray) -> np.ndarray:
    """``Q.T @ W`` in double precision.  A single-precision basis is widened a block of
    rows at a time: numpy would otherwise convert the whole of Q into a temporary."""
    if Q.dtype == np.float64:
        return Q.T @ W
    h = np.zeros((Q.shape[1], W.shape[1]))
    for start in range(0, Q.shape[0], _SWEEP_ROWS):
        h += Q[start : start + _SWEEP_ROWS].astype(np.float64).T @ W[start : start + _SWEEP_ROWS]
    return h


def _subtract_basis_times(W: np.ndarray, Q: np.ndarray, h: np.ndarray) -> None:
    """``W -= Q @ h`` in double precision, in place (a single-precision Q is widened a
    block of rows at a time, as in :func:`_basis_t_times`)."""
    if Q.dtype == np.float64:
        W -= Q @ h
        return
    for start in range(0, Q.shape[0], _SWEEP_ROWS):
        W[start : start + _SWEEP_ROWS] -= Q[start : start + _SWEEP_ROWS].astype(np.float64) @ h


def _orthonormal_block(
    W: np.ndarray,
    Q: np.ndarray,
    rng: np.random.Generator,
    local: int = 0,
    project: Callable[[np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormalise W (N, b) against the orthonormal columns of Q and among itself:
    block classical Gram-Schmidt, a second pass where the first lost more than half a
    column's norm (DGKS), then Cholesky QR; vanishing columns (an invariant Krylov space)
    are replaced by random directions orthogonal to Q.  ``local`` > 0: W is orthogonal
    to ``Q[:, :local]`` in exact arithmetic (the Lanczos recurrence), so the columns
    from ``local`` on go first and the full passes only remove rounding errors.
    Returns (V, h, Rn) with W_in = Q h + V Rn."""
    W = np.array(W, dtype=np.float64, order="F")  # own copy; Q.T @ W is faster in F order
    if local > 0:
        # local pass, then full passes that only remove rounding errors: two sweeps over
        # the basis (the largest array; these products are memory-bound), a third is rare
        h = np.zeros((Q.shape[1], W.shape[1]))
        Ql = Q[:, local:]
        h[local:] = _basis_t_times(Ql, W)
        _subtract_basis_times(W, Ql, h[local:])
        for _ in range(2):
            before = np.linalg.norm(W, axis=0)
            hp = _basis_t_times(Q, W)
            _subtract_basis_times(W, Q, hp)
            h += hp
            if np.all(np.linalg.norm(W, axis=0) >= 0.5 * before):
                break
    else:
        before = np.linalg.norm(W, axis=0)
        h = _basis_t_times(Q, W)
        # The update of the first pass and the products of the second share one sweep
        # over Q, a block of rows at a time that stays in cache: three sweeps, not four.
        h2 = np.zeros_like(h)
        after_sq = np.zeros(W.shape[1])
        for start in range(0, Q.shape[0], _SWEEP_ROWS):
            Qc = np.asarray(Q[start : start + _SWEEP_ROWS], dtype=np.float64)
            Wc = W[start : start + _SWEEP_ROWS]
            Wc -= Qc @ h
            h2 += Qc.T @ Wc
            after_sq += np.einsum("ij,ij->j", Wc, Wc)
        if np.any(np.sqrt(after_sq) < 0.5 * before):
            _subtract_basis_times(W, Q, h2)
            h += h2
    fast = _cholqr(W)
    if fast is not None:
        return fast[0], h, fast[1]
    V, Rn = np.linalg.qr(W)
    scale = np.abs(np.diag(Rn))
    lost = scale <= 1e-12 * max(float(scale.max(initial=0.0)), 1e-300)
    if np.any(lost):
        # invariant subspace found: continue with fresh directions, coupling zero
        fresh = rng.standard_normal((W.shape[0], int(lost.sum())))
        if project is not None:
            fresh = project(fresh)
        for _ in range(2):
            _subtract_basis_times(fresh, Q, _basis_t_times(Q, fresh))
            keep = V[:, ~lost]
            fresh -= keep @ (keep.T @ fresh)
        V[:, lost] = np.linalg.qr(fresh)[0]
        Rn[lost, :] = 0.0
    return V, h, Rn


def rotate_in_place(Q: np.ndarray, j: int, S: np.ndarray, rows: int = 32768) -> None:
    """``Q[:, :p] = Q[:, :j] @ S`` (S is (j, p), p <= j) a block of rows at a time, so no
    (N, p) temporary, as large as the modes, is needed.  A
    single-precision Q is rotated in double precision, a block at a time, and rounded."""
    p = S.shape[1]
    for start in range(0, Q.shape[0], rows):
        block = Q[start : start + rows]
        block[:, :p] = block[:, :j] @ S


HANDOVER_COLUMNS = 32
"""Converged pairs are handed over (``on_converged``) at most this many at a time, so
that the new arrays they come in stay small beside the basis."""

CLUSTER_RTOL = 1e-3
"""Converged Ritz pairs are handed over early (``on_converged``) only up to a gap: a
pair whose Ritz value lies within this relative distance of the next one's waits for
it, so that a cluster of (nearly) equal eigenvalues is handed over whole and the modes
handed over span the same space as the final ones."""


HANDOVER_GROWTH = 0.5
"""Converged pairs are handed over once at least this share of those handed over so far
(and at least one) are ready: each hand-over reads the whole basis, so handing over
every pair as it converges would cost more than the final rotation of all k vectors.
With it, k pairs come in about ``log(k) / log(1.5)`` hand-overs, the first ones one
or two pairs at a time, while the basis is small."""


def _same_cluster(theta: np.ndarray, i: int) -> bool:
    """Whether the descending Ritz values ``theta[i - 1:i + 1]`` are one cluster."""
    return theta[i] >= theta[i - 1] * (1.0 - CLUSTER_RTOL)


def _whole_clusters(theta: np.ndarray, done: int, handed: int, block: int) -> int:
    """The number of leading pairs that may be handed over: ``done`` converged ones,
    less those in a cluster that reaches past them (see :data:`CLUSTER_RTOL`).  A
    trailing cluster of ``block`` or more equal values waits too: a block Krylov method
    sees at most ``block`` copies of an eigenvalue before rounding brings in the others,
    so such a cluster may have more members to come."""
    ready = min(done, theta.shape[0] - 1)  # the next Ritz value must be there to compare
    while ready > handed and _same_cluster(theta, ready):
        ready -= 1
    first = ready - 1  # the trailing cluster's first pair
    while first > 0 and _same_cluster(theta, first):
        first -= 1
    if ready - first >= block:
        ready = max(handed, first)
    return ready


def _basis_times(Q: np.ndarray, j: int, S: np.ndarray) -> np.ndarray:
    """``Q[:, :j] @ S`` as a new float64 array, a block of rows at a time (a
    single-precision basis is widened one block at a time), the two halves of the rows
    on two threads (the solver's BLAS runs on one)."""
    out = np.empty((Q.shape[0], S.shape[1]))

    def half(bounds: tuple[int, int]) -> None:
        for start in range(bounds[0], bounds[1], _SWEEP_ROWS):
            rows = slice(start, min(start + _SWEEP_ROWS, bounds[1]))
            out[rows] = Q[rows, :j].astype(np.float64, copy=False) @ S

    middle = Q.shape[0] // 2
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(half, [(0, middle), (middle, Q.shape[0])]))
    return out


def block_krylov_schur(
    apply_op: Callable[[np.ndarray], np.ndarray],
    N: int,
    k: int,
    *,
    keep: int,
    block: int,
    max_basis: int,
    tol: float,
    report: ProgressFn,
    max_restarts: int = 60,
    timer: StageTimer | None = None,
    project: Callable[[np.ndarray], np.ndarray] | None = None,
    basis: np.ndarray | None = None,
    on_converged: ConvergedFn | None = None,
) -> tuple[np.ndarray, np.ndarray, int]:
    """The k largest eigenpairs of the symmetric positive definite operator ``apply_op``
    (an (N, b) array to OP times it): theta (k,) descending, Y (N, k) orthonormal Ritz
    vectors (a view into the basis array), and the number of operator columns applied.

    The operator is applied to ``block`` vectors at a time (one pass over a factor serves
    many right-hand sides); ``k <= keep``, ``keep + block <= max_basis <= N - block``.
    Ritz pairs are checked every 64 new vectors and when the basis is full, which
    restarts with its ``keep`` best Ritz vectors; a pair has converged when
    ``|OP y - theta y| <= tol * theta``.  ``project`` removes a known invariant subspace
    (deflated null vectors) from an (N, b) array in place, applied to the start block and
    fresh random directions (apply_op projects its results itself).  ``basis``: the
    (N, max_basis + block) float64 or float32 array for the basis (None: a new float64
    one); a float32 basis is orthonormal to about 1e-7 only (products in double,
    :func:`_basis_t_times`), so ``tol`` >= :data:`.eigen.FLOAT32_BASIS_TOL`.
    ``on_converged(theta, Y)`` receives newly converged leading pairs, largest first, as
    (m,) values and a new (N, m) array, in pieces of about :data:`HANDOVER_COLUMNS`, a
    cluster (:data:`CLUSTER_RTOL`) whole, once :data:`HANDOVER_GROWTH` times as many as
    before are ready; with it, pairs are checked before the basis has k columns too.
    """
    rng = np.random.default_rng(12345)  # a fixed start block: every run is deterministic
    timer = timer or StageTimer()
    b = block
    Q = np.empty((N, max_basis + b)) if basis is None else basis
    if Q.shape != (N, max_basis + b):
        raise ValueError(f"the basis array must be ({N}, {max_basis + b}), not {Q.shape}")
    start = rng.standard_normal((N, b))  # an orthonormal random start block
    if project is not None:
        start = project(start)
    Q[:, :b] = np.linalg.qr(start)[0]
    T = np.zeros((max_basis, max_basis))
    j = 0  # closed columns: OP already applied
    sequence_start = 0  # j of the first block after the last (re)start
    R = np.zeros((b, 0))  # OP Q[:, :j] = Q[:, :j] T[:j, :j] + Q[:, j:j+b] R
    applied = 0
    restarts = 0
    done = 0
    handed = 0  # leading pairs given to on_converged
    check_every = max(1, 64 // b)
    blocks_since_check = 0
    while True:
        with timer("solves"):
            W = apply_op(Q[:, j : j + b])
        applied += b
        # OP times the open block couples (in exact arithmetic) only to the previous
        # block, except right after a (re)start, where it couples to all kept vectors.
        local = j - b if j > sequence_start else 0
        with timer("orthogonalisation"):
            V, h, Rn = _orthonormal_block(W, Q[:, : j + b], rng, local, project)
            Q[:, j + b : j + 2 * b] = V
        T[: j + b, j : j + b] = h
        T[j : j + b, : j + b] = h.T
        j += b
        R = np.zeros((b, j))
        R[:, j - b :] = Rn
        full = j + b > max_basis
        # Ritz pairs are checked every ``check_every`` blocks (an eigh of the projected
        # matrix costs about as much as orthogonalising 64 vectors); with a hand-over,
        # as often as an eigh (about 6 j^3 flops of matrix products) costs at most a
        # sixteenth of the orthogonalisation since the last check (4 N j b per block).
        if on_converged is not None:
            check_every = max(1, int(np.ceil(24.0 * j * j / (N * b))))
        blocks_since_check = (blocks_since_check + 1) % check_every
        too_few = j < k and on_converged is None
        if (too_few or blocks_since_check) and not full:
            report("solving", 0.05 + 0.85 * done / k)
            continue
        with timer("ritz"):
            theta, S, estimates, done = _ritz_pairs(T, R, j, min(k, j), keep, tol)
        report("solving", 0.05 + 0.85 * done / k)
        if on_converged is not None and done < k:
            ready = _whole_clusters(theta, done, handed, b)
            if ready - handed >= max(1, HANDOVER_GROWTH * handed):
                handed = _hand_over(Q, j, theta, S, handed, ready, timer, on_converged)
        if done == k:
            with timer("restarts"):
                rotate_in_place(Q, j, S[:, :k])
            return theta[:k], Q[:, :k], applied
        if not full:
            continue
        if restarts == max_restarts:
            worst = float(np.max(estimates[:k] / np.abs(theta[:k])))
            raise NotConverged(
                f"the eigensolver did not converge after {restarts} restarts "
                f"(worst relative residual {worst:.1e})",
                columns=applied,
            )
        restarts += 1
        # thick restart: the p best Ritz vectors (T their Ritz values), then the open block
        p = min(keep, j - b)
        with timer("restarts"):
            rotate_in_place(Q, j, S[:, :p])
            Q[:, p : p + b] = Q[:, j : j + b]
            T[:] = 0.0
            T[np.arange(p), np.arange(p)] = theta[:p]
            R, j = R @ S[:, :p], p
        sequence_start = j


def _hand_over(Q, j, theta, S, handed: int, ready: int, timer, on_converged) -> int:
    """Give ``on_converged`` the Ritz pairs ``handed:ready`` a few columns at a time
    (each piece is a new (N, m) array), clusters whole; returns ``ready``."""
    while handed < ready:
        stop = min(handed + HANDOVER_COLUMNS, ready)
        while stop < ready and _same_cluster(theta, stop):
            stop += 1
        with timer("handover"):
            on_converged(theta[handed:stop].copy(), _basis_times(Q, j, S[:, handed:stop]))
        handed = stop
    return handed


def _ritz_pairs(T, R, j: int, wanted: int, keep: int, tol: float):
    """(theta descending, S, residual estimates, leading converged count) of the
    projected matrix ``T[:j, :j]`` with the residual coupling R."""
    theta, S = np.linalg.eigh(0.5 * (T[:j, :j] + T[:j, :j].T))
    theta, S = theta[::-1], S[:, ::-1]
    estimates = np.linalg.norm(R @ S[:, : min(keep, j)], axis=0)
    # rounding floor: zero modes make theta[0] up to 1e6 times theta[k]
    floor = 16 * np.finfo(float).eps * abs(theta[0])
    converged = estimates[:wanted] <= np.maximum(tol * np.abs(theta[:wanted]), floor)
    done = int(np.argmin(converged)) if not converged.all() else wanted
    return theta, S, estimates, done
