"""Preview spectra: Rayleigh-Ritz in a reduced space of smooth, locally supported functions.

The fine mesh's own operator K and lumped mass M are projected onto a few thousand
functions on the fine mesh (:mod:`.reduced_space`, after Nasikun, Brandt, Hildebrandt:
*Fast Approximation of Laplace-Beltrami Eigenproblems*, SGP 2018).  The reduced problem
``(P^T K P) y = lambda (P^T M P) y`` is a small generalised eigenproblem; the preview
modes are ``P y``.  Galerkin eigenvalues are upper bounds of the fine mesh's
(Courant-Fischer), and the prolonged modes are exactly Mass-orthonormal on the fine mesh.
For the Discrete Shells the space holds the six rigid motions, which are therefore exact
zero modes of the reduced problem.

For the 3D shells the Galerkin modes are then corrected by Rayleigh-Ritz with their
residuals preconditioned by a single-precision factorisation of the fine operator
(:func:`_factor_steps`; a LOBPCG step): curved meshes with thin parts lock any smooth
space (the Galerkin values of spot Loop x3 are 46 % off), and one such step brings the
lowest 50 of 100 eigenvalues within 1.5 % at about a quarter of the exact solve's time;
a refined preview takes a second step where the estimate calls for it.  The same
preconditioned residuals give each mode's estimated error.

Where that factor does not fit the memory limit, and for the normal shells, a two-level
step follows the Galerkin projection instead: Rayleigh-Ritz in the reduced space
enlarged by the block-Jacobi preconditioned residuals of the Galerkin modes, which adds
the mesh-scale parts of the modes (the tangential give of a bumpy surface bending without
stretching) that no smooth space holds.  Where the estimated error then stays above 2 %
for the 3D shells, two steps of subspace iteration with a double-precision factorisation
of the fine operator refine the preview (:func:`_subspace_step`).

The accuracy of each preview mode is reported by its relative residual on the fine mesh,
``|K u - lambda M u|_{M^-1} / (lambda |u|_M)``, and an estimate of its eigenvalue's
relative error (see :func:`estimated_errors`).
"""

from __future__ import annotations

import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .assembly import operator_matrices
from .eigen import (
    CancelFn,
    Cancelled,
    EigenError,
    ProgressFn,
    StageTimer,
    factor_below_spectrum,
    factor_budget_mb,
    lowest_share,
    typical_eigenvalue,
    zero_mode_size,
    zero_modes,
)
from .exact import exact_pairs
from .factor import FactorTooLarge, SPDSolver
from .memory import memory_limit_mb, resident_mb
from .mesh import Mesh, MeshError
from .nullspace import NullSpace, null_space
from .operators import OPERATOR_INFO, SpaceSettings, operator_info
from .products import (
    chunked_projection,
    row_block_sums,
    row_blocks,
    threaded_product,
    threaded_projection,
    transform_columns_in_place,
)
from .reduced_space import (
    ReducedBasis,
    max_samples,
    reduced_basis,
    scalar_functions_per_sample,
)
from .spectrum import Spectrum
from .threads import blas_limit
from .transfer import CoarseCopy

__all__ = [
    "SpaceSettings",
    "SPACE_SETTINGS",
    "preview_possible",
    "preview_spectrum",
    "estimated_errors",
    "compute_preview",
]


SPACE_SETTINGS: dict[str, SpaceSettings] = {
    name: info.preview for name, info in OPERATOR_INFO.items()
}
"""How the reduced space is built per operator (:attr:`.operators.OperatorInfo.preview`)."""


MAX_NULL_COLUMNS = 96
"""Exact null vectors (:mod:`.nullspace`) are added to the reduced space up to this
many (a mesh of many components, e.g. a broken scan, has six rigid motions each)."""


_IN_EVERY_SPACE = ("constants", "rigid motions")
"""Null-space rules (:data:`.operators.NULL_SPACE_RULES`) whose vectors every reduced
space of a connected mesh holds: the partition of unity sums to the constant, and the
3-vector spaces hold the translations and the rotation columns."""


def _null_space_complement(
    mesh, operator, K, mass, basis: ReducedBasis, Mr, nulls: NullSpace | None = None
) -> np.ndarray | None:
    """Dense columns that complete the reduced space to contain the operator's exact null
    vectors (constants and rigid motions per connected component), or None.

    On a connected mesh the Laplacian's constant and the shells' rigid motions are in the
    space by construction (the partition of unity, the rotation columns), so nothing is
    computed.  Otherwise the Mass-orthogonal projection of each null vector onto the
    reduced space is removed; what remains (for example the rotations of a second
    component, or its constant where basis functions straddle two components) is
    Mass-orthonormalised, and parts below 1e-8 of the vector are dropped (already
    contained).  ``nulls``: the null space where it is already computed (a coarse start
    that fell back to the smooth space).
    """
    if mesh.n_components == 1 and operator_info(operator).null_space_rule in _IN_EVERY_SPACE:
        return None
    Z = (null_space(mesh, operator, K, mass) if nulls is None else nulls).vectors
    if Z.shape[1] == 0 or Z.shape[1] > MAX_NULL_COLUMNS:
        return None
    Z = Z.toarray()
    MZ = mass[:, None] * Z
    rhs = basis.restrict(MZ)
    import scipy.linalg as la

    try:
        if Mr.shape[0] <= 4000:
            c = la.cho_solve(la.cho_factor(Mr.toarray()), rhs)
        else:
            c = SPDSolver(Mr).solve(rhs)
    except np.linalg.LinAlgError:  # numerically dependent functions: least squares
        w, V = la.eigh(Mr.toarray())
        keep = w > 1e-12 * w.max()
        c = V[:, keep] @ ((V[:, keep].T @ rhs) / w[keep, None])
    R = Z - basis.prolong(c)
    G = R.T @ (mass[:, None] * R)
    w, V = np.linalg.eigh(0.5 * (G + G.T))
    keep = w > 1e-16 * max(1.0, float(np.max(np.diag(Z.T @ MZ))))
    if not keep.any():
        return None
    return R @ (V[:, keep] / np.sqrt(w[keep]))


def _extend(A: sp.csr_matrix, K, basis: ReducedBasis, E: np.ndarray) -> sp.csr_matrix:
    """``[P E]^T K [P E]`` from ``A = P^T K P`` (E dense)."""
    KE = np.asarray(K @ E)
    cross = basis.restrict(KE)
    B = sp.bmat([[A, sp.csr_matrix(cross)], [sp.csr_matrix(cross.T), sp.csr_matrix(E.T @ KE)]])
    return (0.5 * (B + B.T)).tocsr()


def _kron_projection(K: sp.csr_matrix, Ps: sp.csr_matrix) -> sp.csr_matrix:
    """``kron(Ps, I3)^T K kron(Ps, I3)`` for a symmetric (3n, 3n) K in vertex-major
    order: block (a, b) of every 3 x 3 entry is ``Ps^T K_ab Ps`` with ``K_ab = K[a::3,
    b::3]``; the six with a <= b are computed (two threads, each by row chunks:
    :func:`.products.chunked_projection`), the others are their transposes: a third
    fewer multiply-adds than through the 3n rows."""
    pairs = [(a, b) for a in range(3) for b in range(a, 3)]

    def block(ab: tuple[int, int]) -> sp.coo_matrix:
        a, b = ab
        return chunked_projection(K[a::3][:, b::3], Ps).tocoo()

    with ThreadPoolExecutor(2) as pool:
        blocks = list(pool.map(block, pairs))
    rows, cols, vals = [], [], []
    for (a, b), A in zip(pairs, blocks, strict=True):
        rows.append(3 * A.row + a)
        cols.append(3 * A.col + b)
        vals.append(A.data)
        if a != b:
            rows.append(3 * A.col + b)
            cols.append(3 * A.row + a)
            vals.append(A.data)
    m = 3 * Ps.shape[1]
    return sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(m, m)
    )


def _with_dense_columns(A: sp.csr_matrix, K, basis: ReducedBasis) -> sp.csr_matrix:
    """``P^T K P`` (symmetrised) from its sparse part ``A`` (K sparse or diagonal)."""
    D = basis.dense
    if D is not None:
        KD = K @ D
        cross = basis.restrict(KD)[: basis.n_sparse]
        A = sp.bmat([[A, sp.csr_matrix(cross)], [sp.csr_matrix(cross.T), sp.csr_matrix(D.T @ KD)]])
    A = 0.5 * (A + A.T)
    return A.tocsr()


def _project(K, basis: ReducedBasis) -> sp.csr_matrix:
    """``P^T K P`` as a sparse symmetric matrix; for three components through the
    scalar functions (see :func:`_kron_projection`)."""
    K = sp.csr_matrix(K)
    if basis.components == 3:
        A = _kron_projection(K, basis.scalar)
    else:
        A = threaded_projection(K, basis.scalar)
    return _with_dense_columns(A, K, basis)


def _project_mass(mass: np.ndarray, basis: ReducedBasis) -> sp.csr_matrix:
    """``P^T diag(mass) P``.  With three components the mass repeats each vertex's value
    three times, so the sparse part is ``kron(Ps^T diag(m) Ps, I3)``."""
    Ps, c = basis.scalar, basis.components
    A = threaded_projection(sp.diags(mass[::c]).tocsr(), Ps)
    if c > 1:
        A = sp.kron(A, sp.eye(c), format="csr")
    return _with_dense_columns(A, sp.diags(mass), basis)


DENSE_REDUCED = 4000
"""Reduced problems up to this size are solved densely: 130k shells, 100 modes, 1803 /
2703 / 3603 unknowns: 0.38 / 1.24 / 2.73 s dense against 0.97 / 1.93 / 3.34 s by the
block Lanczos iteration."""


NEGATIVE_RTOL = 1e-6
"""Galerkin eigenvalues below ``-NEGATIVE_RTOL`` times the typical diagonal ratio are
taken for rounding of a singular mass matrix (see :func:`_dense_lowest`)."""


def _dense_lowest(pencil, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Lowest k pairs of the dense symmetric pencil ``A y = lam B y``, Y B-orthonormal;
    ``pencil()`` makes (A, B), fresh Fortran-ordered arrays the solver may overwrite (it
    is called again for the second way below).

    LAPACK's expert driver, working in A's and B's memory; where B is singular
    (functions that vanish on the mesh, or linearly dependent columns) the problem is
    solved on the B-orthonormal eigenbasis of B's range instead.  A is positive
    semi-definite (an energy's Hessian), so a clearly negative eigenvalue means B is
    singular in all but rounding (a thin torus's 192 samples of 3 linear functions on
    1152 vertices gave -2323 where the lowest is 278) and takes the second way too."""
    import scipy.linalg as la

    A, B = pencil()
    typical = float(np.median(np.abs(np.diag(A)) / np.maximum(np.diag(B), 1e-300)))
    try:
        lam, Y = la.eigh(
            A, B, subset_by_index=[0, k - 1], driver="gvx", overwrite_a=True, overwrite_b=True
        )
        if lam[0] >= -NEGATIVE_RTOL * typical:
            return lam, Y
    except np.linalg.LinAlgError:
        pass
    A, B = pencil()
    d = 1.0 / np.sqrt(np.maximum(np.diag(B), 1e-300))
    w, E = la.eigh(B * np.outer(d, d))
    del B
    keep = w > 1e-12 * w.max()
    T = (E[:, keep] / np.sqrt(w[keep])) * d[:, None]
    del E
    lam, Z = la.eigh(T.T @ A @ T, subset_by_index=[0, min(k, int(keep.sum())) - 1])
    return lam, T @ Z


def _solve_reduced(
    Kr: sp.csr_matrix, Mr: sp.csr_matrix, k: int, tol: float = 1e-6
) -> tuple[np.ndarray, np.ndarray]:
    """Lowest k pairs of ``Kr y = lam Mr y``, Y Mr-orthonormal.

    Block Lanczos on ``(Kr - s Mr)^-1 Mr`` (shift s just below zero, one sparse
    factorisation solving blocks of right-hand sides) with full re-orthogonalisation in
    the Mr inner product, and Rayleigh-Ritz with Kr; the basis grows until the k lowest
    pairs have relative residuals below ``tol``.  Problems up to ``DENSE_REDUCED``
    unknowns are solved densely (LAPACK's expert driver for the k lowest pairs).
    """
    N = Kr.shape[0]
    if N <= max(DENSE_REDUCED, 3 * k):
        return _dense_lowest(lambda: (Kr.toarray(order="F"), Mr.toarray(order="F")), k)
    typical = float(np.median(np.abs(Kr.diagonal()) / Mr.diagonal()))
    shift = -1e-6 * (typical or 1.0)
    for _ in range(8):
        try:
            solve = SPDSolver((Kr - shift * Mr).tocsr()).solve
            break
        except np.linalg.LinAlgError:
            shift *= 10.0
    else:
        raise EigenError("the reduced eigenproblem could not be factored")
    b = 32
    V = np.empty((N, 0))
    MV = np.empty((N, 0))
    KV = np.empty((N, 0))
    X = np.random.default_rng(0).standard_normal((N, b))
    check_at = min(N, int(2.2 * k))
    while True:
        for _ in range(2):  # block classical Gram-Schmidt, twice
            X -= V @ (MV.T @ X)
        MX = Mr @ X
        G = X.T @ MX
        w, E = np.linalg.eigh(0.5 * (G + G.T))
        keep = w > 1e-12 * max(w.max(), 1e-300)
        X = X @ (E[:, keep] / np.sqrt(w[keep]))
        MX = Mr @ X
        V = np.hstack([V, X])
        MV = np.hstack([MV, MX])
        KV = np.hstack([KV, Kr @ X])
        s = V.shape[1]
        if s >= check_at or s + b > N or X.shape[1] == 0:
            H = V.T @ KV
            lam, Z = np.linalg.eigh(0.5 * (H + H.T))
            lam, Z = lam[:k], Z[:, :k]
            R = KV @ Z - (MV @ Z) * lam
            scale = np.abs(lam)
            scale[zero_modes(lam, typical)] = max(float(np.abs(lam).max()), typical)
            res = np.linalg.norm(R, axis=0) / scale / np.linalg.norm(MV @ Z, axis=0)
            if res.max() <= tol or s + b > N or X.shape[1] == 0:
                return lam, V @ Z
            check_at = s + 2 * b
        X = solve(MX)


def _jacobi_blocks(K: sp.csr_matrix, block: int):
    """Inverse of the diagonal ``block`` x ``block`` blocks of K, as a function of
    (rows of R, rows) for a slice of whole blocks."""
    K = sp.csr_matrix(K)
    N = K.shape[0]
    if block == 1:
        d = K.diagonal()
        d = np.where(d > 0, d, d.max() if d.size else 1.0)
        return lambda R, rows: R / d[rows, None]
    rows = np.repeat(np.arange(N), np.diff(K.indptr))
    inside = rows // block == K.indices // block
    B = np.zeros((N // block, block, block))
    B[rows[inside] // block, rows[inside] % block, K.indices[inside] % block] = K.data[inside]
    # a tiny multiple of the trace keeps blocks of rigid-free directions invertible
    trace = np.trace(B, axis1=1, axis2=2)
    B += (1e-12 * np.maximum(trace, trace.max() * 1e-12))[:, None, None] * np.eye(block)
    Binv = np.linalg.inv(B)

    def apply(R, rows: slice):
        c = R.shape[1]
        inv = Binv[rows.start // block : rows.stop // block]
        return np.matmul(inv, R.reshape(-1, block, c)).reshape(-1, c)

    return apply


TWO_LEVEL_BLOCK_COLUMNS = 16
"""Columns of the two-level step's float32 directions W widened to double at a time for
``K W``: one (N, 16) block beside U and W, where W in double precision would add half an
(N, k) array (the 337k plate's normal shells, 300 modes: the fast preview's peak 2571 MB
with W in double precision, 2233 MB so, in 1.05 to 1.08 times the time; the exact
solve 2402 MB: benchmarks/results/growth_k300.json)."""


def _two_level_step(K, mass, basis: ReducedBasis, Kr, Mr, lam, U, precondition):
    """Rayleigh-Ritz in ``span [P, W]``: the reduced space together with the
    block-Jacobi preconditioned residuals W of the Galerkin modes U.

    The smooth space holds the modes' large scales and W their mesh-scale parts (the
    tangential give of a bumpy surface bending without stretching) that no smooth space
    holds; taking both whole, rather than W beside the Galerkin modes alone, lets the
    large scales readjust to the fine corrections (130k plate, shells, lowest 50
    eigenvalues: 0.66 % largest error against 2.2 % with ``span [U, W]``).  The space
    contains P, so every Ritz value is at most the Galerkin one and still an upper bound
    of the exact eigenvalue.

    Memory: only U and W are alive, W in single precision (half an (N, k) float64
    array): it only spans the space, and the projected matrices are formed in double
    precision from its stored values, so the Ritz pairs are those of exactly that space.
    ``K U`` is formed a row block at a time (:func:`.products.row_block_sums`) for the
    residuals, ``K W`` (by row blocks too) for a block of
    :data:`TWO_LEVEL_BLOCK_COLUMNS` columns of W widened to double at a time for the
    projections ``P^T K W`` and ``W^T K W``, and the new modes are written into U's
    memory.  Returns (lam, X) with as many pairs as U has columns.
    """
    N, c = U.shape
    W = np.empty(U.shape, dtype=np.float32)

    def residuals(rows, KU):
        R = KU - (mass[rows, None] * U[rows]) * lam[None, :]
        D = precondition(R, rows)
        W[rows] = D
        return np.einsum("ij,ij->j", D, mass[rows, None] * D)

    norms = row_block_sums(K, U, residuals)
    # unit Mass norm; residuals of (numerically) converged pairs add nothing
    norms = np.sqrt(norms)
    live = norms > 1e-10 * max(float(norms.max()), 1e-300)
    W = W[:, live] if not live.all() else W
    W /= norms[live][None, :]

    # K W for a block of W's columns widened to double at a time, by row blocks: a sparse
    # product with the float32 W itself would convert all of W at every row block
    def projections(rows, KW):
        return basis.restrict_rows(KW, rows), W[rows].T.astype(np.float64) @ KW

    width = W.shape[1]
    H_pw, H_ww = np.empty((basis.dimension, width)), np.empty((width, width))
    for j in range(0, width, TWO_LEVEL_BLOCK_COLUMNS):
        cols = slice(j, min(j + TWO_LEVEL_BLOCK_COLUMNS, width))
        H_pw[:, cols], H_ww[:, cols] = row_block_sums(K, W[:, cols].astype(np.float64), projections)
    G_pw = np.zeros_like(H_pw)
    G_ww = np.zeros_like(H_ww)
    for rows in row_blocks(N):
        Wr = W[rows].astype(np.float64)
        MW = mass[rows, None] * Wr
        G_pw += basis.restrict_rows(MW, rows)
        G_ww += Wr.T @ MW

    def pencil():
        H = np.block([[Kr.toarray(), H_pw], [H_pw.T, 0.5 * (H_ww + H_ww.T)]])
        G = np.block([[Mr.toarray(), G_pw], [G_pw.T, 0.5 * (G_ww + G_ww.T)]])
        return H.T, G.T  # Fortran order (symmetric), so LAPACK works in their memory

    new_lam, C = _dense_lowest(pencil, c)
    dim = Kr.shape[0]
    X = basis.prolong(C[:dim], out=U)
    for rows in row_blocks(N):
        X[rows] += W[rows].astype(np.float64) @ C[dim:]
    return new_lam, X


def _residual_norms(K, mass, lam, U, lam_scale, precondition):
    """(relative residuals ``|K u - lam M u| / |lam M u|`` (zero modes: relative to
    lam_max), preconditioned residual norms ``r^T D^-1 r``) in one pass over K's row
    blocks (D the block-Jacobi preconditioner ``precondition``; ``K U`` a block at a
    time, no (N, k) temporaries)."""
    scale = np.abs(lam).copy()
    scale[zero_modes(lam, lam_scale)] = zero_mode_size(lam, lam_scale)

    def sums(rows, KU):
        MU = mass[rows, None] * U[rows]
        R = KU - MU * lam[None, :]
        return (
            np.einsum("ij,ij->j", R, R),
            np.einsum("ij,ij->j", MU, MU),
            np.einsum("ij,ij->j", R, precondition(R, rows)),
        )

    res2, mu2, eta = row_block_sums(K, U, sums)
    return np.sqrt(res2) / (scale * np.sqrt(mu2)), eta


ESTIMATE_MODES = 8
"""Modes (evenly spread over the non-zero ones) whose errors are estimated by conjugate
gradients in :func:`estimated_errors`; the others follow by the ratio measured there."""

ESTIMATE_STEPS = 12
"""Conjugate-gradient steps of :func:`estimated_errors`."""


def _cg_energies(K, R: np.ndarray, precondition, steps: int) -> np.ndarray:
    """``r^T e_m`` for every column r of R, with e_m the m-th iterate (m = ``steps``) of
    preconditioned conjugate gradients on ``K e = r`` from zero, one independent
    iteration per column.  It grows monotonically with m to ``r^T K^-1 r`` (for r in the
    range of K; a column whose iteration breaks down keeps its last value).

    The iterates themselves are never formed: ``r^T p_k = r_k^T z_k`` (the search
    directions are K-conjugate), so ``r^T e_m`` is the sum of ``alpha_k r_k^T z_k``
    (the form Strakos and Tichy use for the energy norm of the error, stable in
    floating point)."""
    N = R.shape[0]
    whole = slice(0, N)
    # every (N, s) array is allocated once: fresh pages cost more than the arithmetic
    res = np.array(R, order="C")
    P = np.ascontiguousarray(precondition(res, whole))
    KP = np.empty(R.shape)
    scratch = np.empty(R.shape)
    rz = np.einsum("ij,ij->j", res, P)
    energy = np.zeros(R.shape[1])
    for _ in range(steps):
        threaded_product(K, P, out=KP)
        pkp = np.einsum("ij,ij->j", P, KP)
        live = (pkp > 0) & (rz > 0)
        alpha = np.where(live, rz / np.where(live, pkp, 1.0), 0.0)
        energy += alpha * rz
        res -= np.multiply(KP, alpha, out=scratch)
        Z = precondition(res, whole)
        rz_new = np.einsum("ij,ij->j", res, Z)
        beta = np.where(live, rz_new / np.where(rz > 0, rz, 1.0), 0.0)
        P *= beta
        P += Z
        rz = np.where(live, rz_new, 0.0)
    return energy


def estimated_errors(
    K,
    mass: np.ndarray,
    lam: np.ndarray,
    U: np.ndarray,
    precondition,
    eta: np.ndarray,
    lam_scale: float = 0.0,
    modes: int = ESTIMATE_MODES,
    steps: int = ESTIMATE_STEPS,
) -> tuple[np.ndarray, float]:
    """(k,) estimated relative eigenvalue errors of the Ritz pairs (lam, U) (zero modes:
    0), and the scale factor c below.

    For a Ritz pair with residual ``r = K u - lam M u`` (u Mass-normalised) the
    eigenvalue's error is to first order ``lam - lam* ~ r^T (K - lam* M)^-1 r``, about
    ``r^T K^-1 r`` where the error lies in modes well above lam*.  For ``modes`` modes
    evenly spread over the non-zero ones, ``steps`` steps of block-Jacobi preconditioned
    conjugate gradients on ``K e = r`` give ``r^T e``, which grows monotonically towards
    ``r^T K^-1 r`` (:func:`_cg_energies`); the others take their preconditioned
    residual norm ``eta = r^T D^-1 r`` times c, the median of ``r^T e / eta`` over those
    modes.  The estimate is therefore a lower estimate that approaches the first-order
    error from below (how close it comes: "Preview spectra" in docs/how-it-works.md).
    """
    out = np.zeros(len(lam))
    nz = np.flatnonzero(~zero_modes(lam, lam_scale) & (eta > 0))
    if nz.size == 0:
        return out, 0.0
    picks = nz[np.unique(np.linspace(0, nz.size - 1, min(modes, nz.size)).round().astype(int))]
    Up = np.ascontiguousarray(U[:, picks])
    R = threaded_product(K, Up) - mass[:, None] * Up * lam[picks]
    energies = _cg_energies(K, R, precondition, steps)
    c = float(np.median(energies / eta[picks]))
    out[nz] = c * eta[nz] / np.abs(lam[nz])
    return out, c


def _block_jacobi_estimate(K, mass, lam, U, lam_scale, precondition):
    """(relative residuals, estimated errors, how they were estimated) of the pairs
    (lam, U): :func:`_residual_norms` and :func:`estimated_errors`."""
    res, eta = _residual_norms(K, mass, lam, U, lam_scale, precondition)
    est, scale = estimated_errors(K, mass, lam, U, precondition, eta, lam_scale)
    method = {
        "method": "block-Jacobi conjugate gradients",
        "modes": ESTIMATE_MODES,
        "steps": ESTIMATE_STEPS,
        "scale": scale,
    }
    return res, est, method


REFINE_ABOVE = 0.02
"""A preview whose largest estimated error is above this (the 2 % the previews aim at)
is refined by subspace iteration with the fine operator (:func:`_subspace_step`)."""

REFINE_STEPS = 2
"""Subspace-iteration steps of a 3D shells refinement.  Always both: after one step the
last pairs' error lies in the modes just above them, which the estimate does not see.
The scalar operators' previews start far closer (about 1 % off), and one step takes them
to 0.01 % (see :mod:`.operators`)."""


ROW_CHUNK = 2048
"""Rows per chunk of the refinement's passes over (N, c) arrays: the dense
(N, c) x (c, c) products are written in place chunk by chunk, so no second (N, c) array
is alive at once.  A pass holds three or four (rows, c) float64 temporaries (a float32
block widened, two products, their sum): 1.6 MB each at 100 modes.  In a compute
process serving every array from the heap (:mod:`modalviewer.processes.memory`) the
refined E_D^N preview of spot Loop x2 (47k) peaked at 280 to 282 MB with 2048 rows and
293 to 311 MB with 16384 (the exact solve: 287 to 288 MB); the cow Loop x3's (186k)
refined Laplacian preview took the same time and memory with either (paired runs)."""


BLOCK_BYTES = 80e6
"""Bytes of an (N, w) block of the refinement's solves and sparse products: the solver
copies its right-hand sides and solutions (Fortran order) and ``K Y`` is formed a block
at a time, so these temporaries stay small beside the (N, c) arrays.  The width is 8 to
16 columns (:func:`_block_columns`): PARDISO's own work arrays for a solve grow with its
columns, and the cow Loop x3's refined Laplacian preview peaked at 867 MB with 32
columns and 759 MB with 16 (median of four runs each, the exact solve: 715 MB), 3 %
slower."""


def _block_columns(n: int) -> int:
    return int(np.clip(BLOCK_BYTES // (8 * max(n, 1)), 8, 16))


def _rows(n: int):
    return (slice(i, min(i + ROW_CHUNK, n)) for i in range(0, n, ROW_CHUNK))


def _weighted_product(A: np.ndarray, B: np.ndarray, weights: np.ndarray | None = None):
    """``A^T diag(weights) B`` (no weights: ``A^T B``) in float64 by row chunks, so a
    float32 A or B is widened a chunk at a time, never whole."""
    out = np.zeros((A.shape[1], B.shape[1]))
    for rows in _rows(A.shape[0]):
        right = B[rows] if weights is None else weights[rows, None] * B[rows]
        out += A[rows].T.astype(np.float64, copy=False) @ right.astype(np.float64, copy=False)
    return out


def _remove_parts_along(Z: np.ndarray, X: np.ndarray, mass: np.ndarray, run=None) -> None:
    """``X -= Z (Z^T M X)`` in place, a row block at a time (no (N, m) temporary): X
    made Mass-orthogonal to the Mass-orthonormal columns of Z (the exact null vectors).
    ``run(n, fn)`` calls ``fn(rows)`` for the row blocks (:func:`_parallel_rows`);
    by default one after another."""
    C = _weighted_product(Z, X, mass)

    def project(rows):
        X[rows] -= Z[rows] @ C

    if run is None:
        for rows in _rows(X.shape[0]):
            project(rows)
    else:
        run(X.shape[0], project)


def _subspace_step(
    K,
    mass: np.ndarray,
    solver,
    lam: np.ndarray,
    U: np.ndarray,
    live=None,
    solved=None,
    beyond=0,
    columns=None,
):
    """Rayleigh-Ritz in ``span [U, S M U]`` with ``S = (K - shift M)^-1`` (shift below
    the spectrum; ``solver`` holds its factorisation): one step of shifted subspace
    iteration that keeps U in the space, so no Ritz value rises.

    U is an (N, b) C-contiguous buffer whose first ``live`` columns (default: all) are
    Ritz pairs with values lam (``U^T K U = diag(lam)``, U Mass-orthonormal).  It is
    overwritten in place: on return its first m columns hold the m = min(b, dimension of
    the space) lowest Ritz pairs, Mass-orthonormal; returns their values (m,).

    Subspace iteration multiplies each mode's share by ``1 / (lam - shift)``, so modes a
    smooth space misses come in after one step.  ``solved``: only U's first ``solved``
    live columns are solved for (default: all); the others stay in the space as they are.
    ``beyond``: the returned values go on to the space's ``beyond`` lowest Ritz values
    where it has that many (the ones past m without vectors), for the estimate's
    reference value (:func:`_refine`).  ``columns``: the solves' block width (default
    :func:`_block_columns`).

    Memory: beside U and the factor, the new directions Y (live columns, float32: they
    only span the space; the projected K and Mass matrices are formed from the stored
    values, so the Ritz pairs are those of exactly that space) and two (N, 8 to 32)
    float64 blocks (:data:`BLOCK_BYTES`): right-hand sides and solutions, then a block of
    Y and its product with K, both reused throughout.  Each solved block is Mass-normalised (a zero
    mode's column is 1/|shift| times larger than the rest) and orthogonalised against U
    in float64 before it is stored; directions left with less than 1e-6 of their norm
    (converged pairs: already in U) are dropped, the rest whitened in place."""
    import scipy.linalg as la

    n, b = U.shape
    u = b if live is None else int(live)
    Uw = U[:, :u]
    v = u if solved is None else min(u, int(solved))
    Y = np.empty((n, v), dtype=np.float32)
    step = _block_columns(n) if columns is None else int(columns)
    rhs = np.empty((n, step), order="F")
    for j in range(0, v, step):
        cols = slice(j, min(j + step, v))
        B = rhs[:, : cols.stop - j]
        np.multiply(mass[:, None], Uw[:, cols], out=B)
        Z = solver.solve(B)
        Z /= np.sqrt(np.einsum("ij,ij,i->j", Z, Z, mass))
        C = _weighted_product(Uw, Z, mass)
        for rows in _rows(n):  # Z - U C and its float32 copy, a row chunk at a time
            Y[rows, cols] = Z[rows] - Uw[rows] @ C
        del Z
    del rhs, B
    gram = _weighted_product(Y, Y, mass)
    norms = np.sqrt(np.diag(gram))
    ok = np.flatnonzero(norms > 1e-6)
    scaled = gram[np.ix_(ok, ok)] / np.outer(norms[ok], norms[ok])
    w, E = np.linalg.eigh(0.5 * (scaled + scaled.T))
    kept = w > 1e-10 * max(float(w.max(initial=0.0)), 1e-300)
    A = np.zeros((v, int(kept.sum())))
    A[ok] = E[:, kept] / np.sqrt(w[kept]) / norms[ok, None]
    Y = transform_columns_in_place(Y, A)
    width = Y.shape[1]
    H_uy, H_yy = np.empty((u, width)), np.empty((width, width))
    widest = min(step, width)
    block, product = np.empty(n * widest), np.empty(n * widest)  # reused by every block
    Yj = KY = None
    for j in range(0, width, step):
        cols = slice(j, min(j + step, width))
        w = cols.stop - j
        Yj = block[: n * w].reshape(n, w)
        Yj[:] = Y[:, cols]
        KY = threaded_product(K, Yj, out=product[: n * w].reshape(n, w))
        H_uy[:, cols] = Uw.T @ KY
        H_yy[:, cols] = _weighted_product(Y, KY)
    del block, product, Yj, KY
    G_uy = _weighted_product(Uw, Y, mass)
    G_yy = _weighted_product(Y, Y, mass)
    H = np.block([[np.diag(lam[:u]), H_uy], [H_uy.T, 0.5 * (H_yy + H_yy.T)]])
    G = np.block([[np.eye(u), G_uy], [G_uy.T, 0.5 * (G_yy + G_yy.T)]])
    m = min(b, H.shape[0])
    top = min(max(m, int(beyond)), H.shape[0])
    lam, C = la.eigh(H, G, subset_by_index=[0, top - 1])
    for rows in _rows(n):  # X = [U Y] C, written over U row chunk by row chunk
        U[rows, :m] = Uw[rows] @ C[:u, :m] + Y[rows] @ C[u:, :m]
    return lam


STEP_SHIFT = 1.0
"""The single-precision factor of the 3D shells' correction step is of ``K + s M`` with
s this multiple of the lowest non-zero Galerkin eigenvalue (spot Loop x3, 100 modes,
lowest 50 eigenvalues after one step: 1.45 % largest error at 1.0, 2.6 % at 0.1; at
0.01 the single-precision factorisation fails as not positive definite)."""

STEP_COLUMNS = 0.6
"""Share of the modes asked for (the lowest non-zero ones) whose residuals the first
correction step preconditions: the solve, the products with K and the Gram matrices
grow with it.  Spot Loop x3 / hand Loop x2 (187k / 206k vertices), 100 modes: 60 of 94
columns keep the lowest 50 eigenvalues within 1.5 / 1.4 % at 0.24 / 0.25 of the exact
time (``benchmarks/results/curved.json``; modes 61 to 94 up to 14 / 16 % off, which
their estimates report); all 94 columns took 0.24 / 0.26 with 1.5 / 0.4 % in a run of
the same script beside an exact solve, and 50 columns left 2.9 % on the hand."""

STEP_REFINE_STEPS = 1
"""Further correction steps (all non-zero modes preconditioned) of a refined preview
where the estimate after the first is above the refinement threshold (spot Loop x3:
1.5 % after one step, 0.015 % after two)."""

STEP_DROP = 1e-10
"""Directions of the correction's space whose scaled Gram eigenvalue is below this times
the largest are dropped (numerically dependent: converged modes' residuals)."""


@dataclass
class ShiftedFactor:
    """A factor of ``K + shift M`` (``shift`` > 0 places it below the spectrum): the
    solver and the shift, which the error estimate needs (:func:`_first_order_errors`)."""

    solver: SPDSolver
    shift: float

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.solver.solve(b)

    @property
    def out_of_core(self) -> bool:
        return self.solver.out_of_core

    @property
    def factor_mb(self) -> float:
        return self.solver.factor_mb


NEIGHBOUR_SHARE_CAP = 0.75
"""Largest share q of :func:`_first_order_errors` taken at face value: the estimate is
at most ``1 / (1 - 0.75) = 4`` times ``r^T S r / lam``.  A larger q comes from residuals
whose modes lie just above the Ritz value or below it (a mode the space resolves poorly
lies below; the normal shells' fast preview of spot Loop x2, 8 % off, has q up to 2.1),
where the one-band reading of the two numbers no longer holds."""


def _first_order_errors(
    lam, shift: float, energies, solution_norms, above: float = np.inf
) -> np.ndarray:
    """Estimated relative errors of Ritz values lam from their residuals r through a
    factor S of ``K + shift M``: ``energies`` ``r^T S r`` and ``solution_norms``
    ``(S r)^T M (S r)``.

    With u = sum c_j phi_j, x_j = lam_j - lam and y_j = lam_j + shift, the error is
    (first order, exact for Ritz pairs) ``sum c_j^2 x_j``, while
    ``A = r^T S r = sum c_j^2 x_j^2 / y_j`` and ``B = |S r|_M^2 = sum c_j^2 x_j^2 / y_j^2``.
    A alone (the error where the residual lies in modes far above lam) reads the error
    of modes just above lam short by the factor ``x / y``: the top modes of a preview,
    2 to 3 times too low (homer Loop x2's 3D shells from a coarse copy: 3.3 % estimated
    where the largest error was 6.8 %).  Where one band of modes carries the residual,
    ``y = A / B`` and the error is ``A / (1 - q)`` with ``q = (lam + shift) B / A``;
    with several bands ``A / (1 - q)`` is still at most the first-order error (Jensen's
    inequality: ``1 / (1 - (lam + shift) t)`` is convex in t = 1/y), so it stays a lower
    estimate, closer than A.  q is capped at :data:`NEIGHBOUR_SHARE_CAP`.

    ``above``: where the pairs come from a space holding the modes up to about that
    value (after subspace steps, :func:`_refine`), the residual lies in modes above it,
    and the error is at most ``A (above + shift) / (above - lam)`` (x / y grows with
    lam_j), which is taken where it is larger: after the steps the errors lie in the
    modes just above the space, which the one-band reading alone read at 0.13 to 0.45
    times the error (spot Loop x1's refined Laplacian and E_D^N)."""
    lam = np.abs(np.asarray(lam, dtype=np.float64))
    energy = np.maximum(np.asarray(energies, dtype=np.float64), 0.0)
    q = np.divide(
        (lam + shift) * np.asarray(solution_norms, dtype=np.float64),
        energy,
        out=np.zeros_like(energy),
        where=energy > 0,
    )
    scale = np.maximum(lam, np.finfo(float).tiny)
    estimate = energy / scale / (1.0 - np.clip(q, 0.0, NEIGHBOUR_SHARE_CAP))
    if np.isfinite(above):
        gap = np.maximum(above - lam, np.finfo(float).tiny)
        estimate = np.maximum(estimate, energy / scale * (above + shift) / gap)
    return estimate


def _parallel_rows(n: int, fn) -> None:
    """``fn(rows)`` for the row blocks of ``range(n)``, the two halves on two threads
    (each dense product on one BLAS thread inside :func:`.threads.blas_limit`)."""
    blocks = list(row_blocks(n))
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda part: [fn(rows) for rows in part], (blocks[0::2], blocks[1::2])))


def _single_factor(K, mass: np.ndarray, lowest: float, columns: int):
    """:class:`ShiftedFactor` of ``K + s M`` in single precision (``s = STEP_SHIFT *
    lowest``, ten times more while it fails), within what the memory limit leaves beside the process
    and the step's arrays (the preconditioned residuals in double precision and the
    solver's single-precision right-hand sides and solutions); None where it would not
    fit or never factors."""
    n = K.shape[0]
    limit = memory_limit_mb()
    budget = None if limit is None else limit - resident_mb() - 16.0 * n * columns / 2**20
    shift = STEP_SHIFT * lowest
    for _ in range(3):
        try:
            solver = SPDSolver(
                K + shift * sp.diags(mass), memory_budget_mb=budget, single_precision=True
            )
            return ShiftedFactor(solver, shift)
        except FactorTooLarge:
            return None
        except np.linalg.LinAlgError:
            shift *= 10.0
    return None


STEP_BLOCK_COLUMNS = 16
"""Columns per block of the 3D shells' preconditioned residuals (:func:`_factor_steps`):
each block's residuals and solutions (float32) and PARDISO's work arrays for its solve
grow with the columns and sit beside the factor and the modes.  The machined part flat
x3 (266k vertices, 57 columns in the first step): the fast preview peaked at 2951 MB in
two runs with blocks of 32 and at 3175 to 3428 MB in five with one block (the exact
solve: 3376 MB), in the same time; spot Loop x3 2722 against 2838 MB, 4 % slower.  With
the guard modes (:data:`SMOOTH_GUARD`) in the space the refined preview peaked at 3356 MB
with blocks of 32 and 2990 MB with blocks of 16 (the exact solve: 3276 MB), its
correction 8 % slower."""


REFINE_BLOCK_COLUMNS = 16
"""Columns per block where a refinement's step keeps all wanted modes' preconditioned
residuals: narrow blocks beside those (N, k) directions keep the refined preview's peak
near the fast one's (the machined part flat x3, 266k vertices: 1.13 times the exact
solve's peak with one block of 94; see :data:`STEP_BLOCK_COLUMNS`)."""


def _preconditioned_residuals(
    K, mass, solver, lam, U, lam_scale, cols: slice, Z, keep: bool, block_columns=None
):
    """(relative residuals of U's columns ``cols``, ``W = F^-1 R`` for their residuals R
    (float64, C-ordered, Mass-orthogonal to the zero modes Z; None unless ``keep``),
    ``r^T F^-1 r`` per column, ``(F^-1 r)^T M (F^-1 r)`` per column), with F the factor
    ``solver`` (a :class:`ShiftedFactor`).

    Columns go in blocks (:data:`STEP_BLOCK_COLUMNS`): one pass over K's row blocks for the
    block's residuals, then one block solve, so only W (where kept) spans all columns."""
    n = U.shape[0]
    width = cols.stop - cols.start
    per_block = STEP_BLOCK_COLUMNS if block_columns is None else int(block_columns)
    W = np.empty((n, width)) if keep else None
    energies, res2, mu2 = np.zeros(width), np.zeros(width), np.zeros(width)
    solution_norms = np.zeros(width)
    lock = threading.Lock()
    for start in range(0, width, per_block):
        stop = min(start + per_block, width)
        block = slice(cols.start + start, cols.start + stop)
        # one block: K times all of U (no copy of its columns; U is C-ordered), else
        # times a copy of the block's columns
        Ub, within = (U, block) if stop - start == width else (U[:, block].copy(), slice(None))
        lam_b = lam[block]
        R = np.empty((n, stop - start), dtype=np.float32, order="F")

        def sums(rows, KU, Ub=Ub, within=within, lam_b=lam_b, R=R):
            MU = mass[rows, None] * Ub[rows, within]
            res = KU[:, within] - MU * lam_b[None, :]
            R[rows] = res
            return np.einsum("ij,ij->j", res, res), np.einsum("ij,ij->j", MU, MU)

        res2[start:stop], mu2[start:stop] = row_block_sums(K, Ub, sums)
        del Ub
        solved = solver.solve(R)

        def widen(rows, R=R, solved=solved, start=start, stop=stop):
            part = solved[rows].astype(np.float64)
            energy = np.einsum("ij,ij->j", R[rows].astype(np.float64), part)
            norm = np.einsum("ij,ij,i->j", part, part, mass[rows])
            if W is not None:
                W[rows, start:stop] = part
            with lock:
                energies[start:stop] += energy
                solution_norms[start:stop] += norm

        _parallel_rows(n, widen)
        del R, solved
    scale = np.abs(lam[cols]).copy()
    zero = zero_modes(lam, lam_scale)[cols]
    scale[zero] = max(float(np.abs(lam).max()), lam_scale)
    relative = np.sqrt(res2) / (scale * np.sqrt(mu2))
    if W is not None and Z.shape[1]:
        _remove_parts_along(Z, W, mass, _parallel_rows)
    return relative, W, energies, solution_norms


def _ritz_with(K, mass, lam, U, W) -> np.ndarray:
    """Rayleigh-Ritz in ``span [U, W]`` (U Mass-orthonormal Ritz vectors with values
    lam, ``U^T K U = diag(lam)``): U's columns are overwritten by the lowest Ritz
    vectors, Mass-orthonormal; returns their values.  The Gram matrices are formed
    explicitly in one pass over K's row blocks (no (N, k) temporaries) and scaled to
    unit diagonal; directions below :data:`STEP_DROP` are dropped, so no
    orthogonalisation pass over the (N, k) arrays is needed.  The space contains U, so
    no Ritz value rises."""
    import scipy.linalg as la

    c = U.shape[1]

    def sums(rows, KW):
        MW = mass[rows, None] * W[rows]
        return U[rows].T @ KW, W[rows].T @ KW, U[rows].T @ MW, W[rows].T @ MW

    H_uw, H_ww, G_uw, G_ww = row_block_sums(K, W, sums)
    H = np.block([[np.diag(lam), H_uw], [H_uw.T, 0.5 * (H_ww + H_ww.T)]])
    G = np.block([[np.eye(c), G_uw], [G_uw.T, 0.5 * (G_ww + G_ww.T)]])
    d = 1.0 / np.sqrt(np.maximum(np.diag(G), 1e-300))
    w, V = la.eigh(G * np.outer(d, d))
    keep = w > STEP_DROP * w.max()
    T = V[:, keep] / np.sqrt(w[keep])
    mu, C = la.eigh(T.T @ (H * np.outer(d, d)) @ T)
    C = d[:, None] * (T @ C[:, :c])
    C_u, C_w = np.ascontiguousarray(C[:c]), np.ascontiguousarray(C[c:])

    def update(rows):
        U[rows] = U[rows] @ C_u + W[rows] @ C_w

    _parallel_rows(U.shape[0], update)
    return mu[:c]


def _zero_mode_residuals(K, mass, lam, U, first: int, lam_scale: float) -> np.ndarray:
    """Relative residuals of the zero modes, U's first ``first`` columns: scaled by the
    largest eigenvalue or ``lam_scale`` (a zero mode has no size of its own)."""
    Z = U[:, :first]
    R = threaded_product(K, Z) - (mass[:, None] * Z) * lam[:first]
    MZ = np.linalg.norm(mass[:, None] * Z, axis=0)
    return np.linalg.norm(R, axis=0) / (zero_mode_size(lam, lam_scale) * MZ)


def _factor_steps(
    K,
    mass,
    lam,
    U,
    lam_scale,
    refine_above,
    max_steps,
    report,
    factored=None,
    give_up=False,
    wanted=None,
):
    """The 3D shells' correction of the Galerkin pairs (lam, U): Rayleigh-Ritz steps
    with the residuals preconditioned by a single-precision factor of the fine operator
    (LOBPCG without its third block), U overwritten in place.

    The first step preconditions the lowest :data:`STEP_COLUMNS` of the ``wanted``
    (default: all) modes' non-zero ones;
    then the residuals of all of them are preconditioned, which gives both the relative
    residuals and the estimated errors (from ``r^T F^-1 r`` and ``|F^-1 r|_M``, F the
    factor: :func:`_first_order_errors`, a lower estimate of the first-order error);
    while the largest estimate is above ``refine_above`` and fewer than ``max_steps``
    further steps were taken, those preconditioned residuals (solved again, kept this
    time) make the next step.  The
    zero modes (the rigid motions, exact in the Galerkin space) are kept out of the new
    directions.  With ``give_up``, where the lower half of the non-zero modes is still
    estimated above ``refine_above`` after the last step, or above
    :data:`GIVE_UP_ABOVE` after an earlier one, no further step is taken and
    ``info["unconverged"]`` is set: modes the smooth space missed altogether (the cow's
    tail: its Galerkin values ten times too high) come in only slowly through a
    preconditioner shifted by ``lam_1``, and subspace iteration shifted near zero finds
    them (the caller's refinement).  ``factored()`` is called once the factor exists
    (the caller lets go of what only the two-level step would need).  Returns (lam,
    relative residuals, estimates, info), or None where the factor does not fit the
    memory limit (the caller takes the two-level step)."""
    zero = zero_modes(lam, lam_scale)
    first = int(np.argmin(zero)) if not zero.all() else lam.shape[0]
    if not zero[:first].all() or zero[first:].any() or first == lam.shape[0]:
        return None  # zero modes first, then the non-zero ones (ascending values)
    c = lam.shape[0]
    asked = c if wanted is None else min(c, int(wanted))
    columns = min(c - first, max(1, int(np.ceil(STEP_COLUMNS * asked))))
    seconds = {}
    t = time.perf_counter()
    report("preview: factorising (single precision)", 0.8)
    solver = _single_factor(K, mass, float(lam[first]), c - first)
    if solver is None:
        return None
    seconds["single_factor"] = time.perf_counter() - t
    if factored is not None:
        factored()
    Z = np.ascontiguousarray(U[:, :first])  # the rigid motions: U's rows stay as they are
    info = {"factor_mb": solver.factor_mb, "columns_first_step": columns, "steps": 0}
    cols = slice(first, first + columns)
    while True:
        t = time.perf_counter()
        report("preview: correcting", min(0.95, 0.85 + 0.04 * info["steps"]))
        # the first step's directions are kept; after it the estimate comes first, without
        # the (N, k) directions, and they are made again only where a further step follows
        # (a solve more, so a refined preview's peak stays that of the fast one)
        keep = info["steps"] == 0
        relative, W, energies, norms = _preconditioned_residuals(
            K, mass, solver, lam, U, lam_scale, cols, Z, keep
        )
        seconds["preconditioned_residuals"] = seconds.get("preconditioned_residuals", 0.0) + (
            time.perf_counter() - t
        )
        if info["steps"]:  # every wanted non-zero mode's residual: the estimate
            res = np.zeros(c)
            res[:first] = _zero_mode_residuals(K, mass, lam, U, first, lam_scale)
            res[cols] = relative
            est = np.zeros(c)
            est[cols] = _first_order_errors(lam[cols], solver.shift, energies, norms)
            info.setdefault("estimated_error_first_step", float(est.max()))
            lower = est[first:][: max(1, int(np.ceil(0.5 * (asked - first))))].max()
            # before the last step only a lower half far off (modes missing) gives up; a
            # lower half a little above the threshold takes the next step
            last = info["steps"] >= 1 + max_steps
            bar = refine_above if last else max(refine_above, GIVE_UP_ABOVE)
            info["unconverged"] = bool(give_up and lower > bar)
            if info["unconverged"] or last or est.max() <= refine_above:
                break
            t = time.perf_counter()
            _, W, _, _ = _preconditioned_residuals(
                K, mass, solver, lam, U, lam_scale, cols, Z, True, REFINE_BLOCK_COLUMNS
            )
            seconds["preconditioned_residuals"] += time.perf_counter() - t
        t = time.perf_counter()
        lam = _ritz_with(K, mass, lam, U, W)
        del W
        info["steps"] += 1
        seconds["rayleigh_ritz"] = seconds.get("rayleigh_ritz", 0.0) + time.perf_counter() - t
        cols = slice(first, min(c, max(first + 1, asked)))  # guard modes stay unsolved
    info["seconds"] = {s: round(v, 4) for s, v in seconds.items()}
    return lam, res, est, info


GIVE_UP_ABOVE = 0.05
"""A refined 3D shells preview whose lower half of non-zero modes is estimated above
this after the first correction step leaves the steps for the caller's subspace
iteration (modes missing: the cow Loop x3's, Cheburashka's and homer's lower halves are
20 to 200 % off after it); between the refinement threshold and this it takes the next
step (the 10k benchmark mesh, spot midpoint-subdivided once, 100 modes: 2.45 % off,
estimated 2.1 %; the second step takes it to 0.09 %, where the subspace iteration took
4.2 s more)."""


REFINE_GUARD = 0.25
"""Guard vectors of the refinement, as a fraction of the modes wanted (at least
:data:`REFINE_GUARD_MIN`): the wanted modes converge faster when the iteration carries a
few more."""

REFINE_GUARD_MIN = 5

REFINE_SHIFT = 0.01
"""The refinement's shift: this fraction of the lowest non-zero preview eigenvalue below
zero.  Subspace iteration multiplies a mode's share by ``1 / (lam - shift)``, so a
shift near zero brings in modes far below the preview's values (modes of thin parts the
smooth space misses), where a shift scaled by the operator's diagonal would not."""


def _factor_below(K, mass: np.ndarray, lam: np.ndarray, lam_scale: float):
    """:class:`ShiftedFactor` of ``K + s M`` with ``s = REFINE_SHIFT * (lowest non-zero
    lam)``, moving further down while the factorisation fails
    (:func:`.eigen.factor_below_spectrum`); None if it never succeeds.  The factor keeps
    within the memory limit (:func:`.memory.memory_limit_mb`) beside what the process
    holds (the Ritz buffer is made before it) and the subspace step's arrays: the new
    directions in float32 (half an (N, c) float64 array) and its (N, w) blocks; where
    it would not fit, it goes out of core (:mod:`.factor`)."""
    positive = lam[~zero_modes(lam, lam_scale)]
    lowest = float(positive.min() if positive.size else lam_scale)
    n = K.shape[0]
    budget = factor_budget_mb(memory_limit_mb(), n, lam.shape[0] // 2, _block_columns(n))
    try:
        solver, shift = factor_below_spectrum(
            K, mass, lowest, lambda *_: None, StageTimer(), REFINE_SHIFT, budget
        )
    except EigenError:
        return None
    return ShiftedFactor(solver, -shift)


def _with_exact_null_vectors(mesh, operator, K, mass, lam, U, res, lam_scale, nulls):
    """(d, null space): where the smooth space's preview starts with as many zero modes
    as the operator has exact null vectors (:mod:`.nullspace`; the reduced space holds
    them, :func:`_null_space_complement`), those Ritz vectors are replaced in place by
    the exact vectors (the same span to rounding: on spot Loop x1's 3D shells the other
    modes kept 3e-10 of them, removed here), their values set to 0 and their residuals
    measured, as the exact solver deflates them; d is their number.  d = 0
    where the counts differ (a space without some of them: more than
    :data:`MAX_NULL_COLUMNS`), and the modes are left as they are."""
    if nulls is None:
        nulls = null_space(mesh, operator, K, mass)
    d = nulls.dimension
    if d == 0 or _leading_zero_modes(lam, lam_scale) != d:
        return 0, nulls
    Z = nulls.vectors.toarray()
    U[:, :d] = Z
    _remove_parts_along(Z, U[:, d:], mass)  # the other modes' parts along Z: rounding
    lam[:d] = 0.0
    res[:d] = _zero_mode_residuals(K, mass, lam, U, d, lam_scale)
    return d, nulls


def _leading_zero_modes(lam: np.ndarray, lam_scale: float) -> int:
    """How many of the ascending values lam are zero modes (:func:`.eigen.zero_modes`)."""
    zero = zero_modes(lam, lam_scale)
    return int(zero.size if zero.all() else np.argmin(zero))


def _refinement_buffer(U: np.ndarray, steps: int, n: int, wanted: int | None = None) -> np.ndarray:
    """A C-contiguous (N, c + guard) array holding the (N, c) modes U in its first
    columns, for :func:`_refine` to write its Ritz vectors over (the caller drops U).
    Guard vectors (:data:`REFINE_GUARD`): the last wanted pairs converge at the rate
    ``lam_c / lam_(c+guard)``; a single step has no next step for them to speed up, so
    it works in U itself (a C-contiguous float64 U that owns its memory is returned, not
    copied: a copy would hold the modes twice beside the factor; a view is copied, so
    that the memory it is a view of can go).  ``wanted``: U's columns beyond it are
    guard modes already (the smooth-space preview's), counted in the guard."""
    c = U.shape[1]
    asked = c if wanted is None else min(c, int(wanted))
    guard = max(REFINE_GUARD_MIN, int(REFINE_GUARD * asked)) if steps > 1 else 0
    width = max(c, min(asked + guard, n // 2))
    if width == c and U.flags.c_contiguous and U.flags.owndata and U.dtype == np.float64:
        return U
    buffer = np.empty((U.shape[0], width))
    buffer[:, :c] = U
    return buffer


def _refine(
    K, mass, solver, lam, buffer: np.ndarray, c: int, steps: int, report, at: float, columns=None
):
    """``steps`` subspace steps (:func:`_subspace_step`) with ``solver`` from the Ritz
    pairs (lam, the buffer's first c columns); the buffer is then shrunk in place to the
    c lowest Ritz vectors, which own its memory.  Returns their values (c,).

    Each step solves for the c wanted pairs only; the guard vectors (the buffer's
    columns past c: filled by the first step's Rayleigh-Ritz, or the smooth-space
    preview's own guard modes) stay in its space unsolved (their new directions would
    only sharpen pairs that are dropped): in the last step of homer Loop x2's 3D
    shells, 100 modes, that gave the same eigenvalues to four digits (largest errors
    0.032 % in the lowest 50, 5.5 % in all), 1.5 to 2 s faster and 15 to 30 MB lower
    at the peak.

    Also returns the reference value of the estimate that follows: the last step's
    Ritz value number ``c +`` :func:`_guard_modes` ``(c)`` (the highest a space of that
    many modes holds; inf where the space is smaller), which
    :func:`_first_order_errors` takes as the lowest eigenvalue the errors can lie in."""
    beyond = c + _guard_modes(c)
    reference = np.inf
    for i in range(steps):
        report("preview: refining", at + 0.02 * i)
        last = i == steps - 1
        values = _subspace_step(  # the wanted pairs solved for, the guard vectors not
            K,
            mass,
            solver,
            lam,
            buffer,
            live=lam.shape[0],
            solved=c,
            beyond=beyond if last else 0,
            columns=columns,
        )
        lam = values[: min(buffer.shape[1], values.shape[0])]
        if last:
            reference = float(values[min(beyond, values.shape[0]) - 1])
    transform_columns_in_place(buffer, c)  # the first c columns to the buffer's start
    buffer.resize((buffer.shape[0], c), refcheck=False)
    return lam[:c], reference


COARSE_SHIFT = 0.5
"""The coarse start's factor is of ``K + s M`` with s this share of the coarse copy's
lowest non-zero eigenvalue (a coarse copy's eigenvalues lie below the mesh's: the cow
decimated to 3 % has them about half as large).  The cow Loop x2's lowest 50 came within
0.96 % at 0.05 times the lowest non-zero eigenvalue and 1.0 % at 7 times; the exact
solver's shift, just above zero, left the cow Loop x3 7.4 % off where this one leaves
0.74 %.  A shift well away from zero also factorises at the first try."""


COARSE_SOLVE_COLUMNS = 16
"""Columns per solve of the coarse start's inverse-iteration step: the right-hand sides
and solutions of a block are its only (N, w) temporaries beside the carried modes and
the factor (Cheburashka Loop x2, 320k unknowns: 40 MB each at 16 columns)."""

COARSE_GUARD = 0.25
"""The coarse start carries this share more of the copy's modes than are asked for
(at least :data:`REFINE_GUARD_MIN`): without them the top few Ritz pairs of the step
can stand for higher modes while a wanted one is missing (a torus's 24th non-zero mode
of 24 carried was 39 % off, its residual estimate 0.2 %)."""


def _coarse_copy_pairs(coarse: CoarseCopy, operator: str, k: int, bending, membrane):
    """(eigenvalues, modes (3 Nc, m)) of the coarse copy's lowest non-zero modes (at most
    ``k``, at most half its unknowns), or None where its operator cannot be solved (a
    decimation can leave non-manifold edges or slivers)."""
    unknowns = operator_info(operator).unknowns(coarse.mesh.n_vertices)
    try:
        pairs = exact_pairs(coarse.mesh, operator, min(int(k), unknowns // 2), bending, membrane)
    except (MeshError, EigenError, np.linalg.LinAlgError, ValueError):
        return None
    if not pairs.nonzero.any():
        return None
    return pairs.result.eigenvalues[pairs.nonzero], pairs.result.vectors[:, pairs.nonzero]


def _ritz_in_span(K, mass: np.ndarray, Y: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` lowest Ritz pairs of ``K x = lam M x`` in the span of Y's columns
    (values, coefficients C: the vectors are ``Y C``, Mass-orthonormal).  The Gram
    matrices are formed in one pass over K's row blocks and scaled to unit diagonal;
    numerically dependent directions (below :data:`STEP_DROP`) are dropped."""
    import scipy.linalg as la

    def sums(rows, KY):
        return Y[rows].T @ KY, Y[rows].T @ (mass[rows, None] * Y[rows])

    H, G = row_block_sums(K, Y, sums)
    d = 1.0 / np.sqrt(np.maximum(np.diag(G), 1e-300))
    w, V = la.eigh(0.5 * (G + G.T) * np.outer(d, d))
    keep = w > STEP_DROP * w.max()
    T = V[:, keep] / np.sqrt(w[keep])
    mu, C = la.eigh(T.T @ (0.5 * (H + H.T) * np.outer(d, d)) @ T)
    count = min(count, mu.shape[0])
    return mu[:count], d[:, None] * (T @ C[:, :count])


def _coarse_start(
    mesh: Mesh,
    operator: str,
    K,
    mass: np.ndarray,
    k: int,
    coarse: CoarseCopy | Future,
    weights,
    report,
    nulls: NullSpace,
):
    """The 3D shells' preview from a coarse copy: (lam, U, solver, info) or None.

    The coarse copy's own lowest modes (its Discrete Shells: a coarse discretisation
    of the same surface, so a thin part's bending modes are there, where a smooth
    space on the fine mesh locks them out) are carried to the mesh
    (:func:`.transfer.displacement_prolongation`); one step of inverse iteration with a
    factor of the fine operator (``Y = (K + s M)^-1 M V``, s :data:`COARSE_SHIFT` times
    the copy's lowest non-zero eigenvalue) adds the mesh-scale parts every carried field
    lacks, and Rayleigh-Ritz in
    ``span [Z, Y]`` (Z the exact null vectors) gives the pairs.  The factor is returned
    for the refinement's steps.  ``coarse`` may be a copy still being made (a
    ``concurrent.futures.Future`` of one, :func:`modalviewer.coarsen.start_preview_copy`):
    it is waited for after the assembly and the null space, which so overlap the
    copy's process (the caller computes ``nulls``, the null space, before it calls).
    None where no copy came out, the coarse copy's spectrum or the factor fails, or the
    copy has fewer non-zero modes than asked for (the caller takes the smooth space)."""
    seconds = {}
    d = nulls.dimension
    if hasattr(coarse, "result"):
        t = time.perf_counter()
        report("preview: making a coarse copy", 0.05)
        coarse = coarse.result()
        seconds["waiting_for_the_copy"] = time.perf_counter() - t
        if coarse is None:  # no usable copy came out
            return None
    t = time.perf_counter()
    report("preview: coarse copy's spectrum", 0.1)
    carried = k + max(REFINE_GUARD_MIN, int(np.ceil(COARSE_GUARD * k)))
    pairs = _coarse_copy_pairs(coarse, operator, carried, *weights)
    if pairs is None:
        return None
    lam_c, modes_c = pairs
    seconds["coarse_spectrum"] = time.perf_counter() - t
    if k <= d or lam_c.shape[0] < k - d:  # the copy holds too few modes
        return None
    t = time.perf_counter()
    # the factor before the carried modes: its factorisation's working memory and the
    # (N, m) carried block are never alive at once.  Double precision: the step replaces
    # the carried modes by its solutions (the smooth space's step only adds directions),
    # and in single precision the cow Loop x3's K + s M does not factorise at this shift
    # nor at 10 times it; at 100 times it the step left eigenvalues 7 times too large.
    report("preview: factorising", 0.3)
    n = K.shape[0]
    budget = factor_budget_mb(memory_limit_mb(), n, k, _block_columns(n))
    try:
        solver, shift = factor_below_spectrum(
            K, mass, float(lam_c[0]), lambda *_: None, StageTimer(), COARSE_SHIFT, budget
        )
    except EigenError:
        return None
    solver = ShiftedFactor(solver, -shift)
    seconds["factor"] = time.perf_counter() - t
    t = time.perf_counter()
    report("preview: carrying the coarse modes", 0.5)
    V = threaded_product(coarse.prolongation(mesh), np.ascontiguousarray(modes_c))
    del modes_c
    seconds["prolongation"] = time.perf_counter() - t
    t = time.perf_counter()
    report("preview: inverse iteration", 0.6)
    m = V.shape[1]
    step = min(_block_columns(n), COARSE_SOLVE_COLUMNS)
    rhs = np.empty((n, step), order="F")  # the solver's own layout: no copy of it is made
    for j in range(0, m, step):  # V overwritten by Y = S M V, a block at a time
        cols = slice(j, min(j + step, m))
        B = rhs[:, : cols.stop - j]
        np.multiply(mass[:, None], V[:, cols], out=B)
        V[:, cols] = solver.solve(B)
    del rhs, B
    Z = nulls.vectors.toarray() if d else np.zeros((n, 0))
    if d:  # Mass-orthogonal to the null vectors
        _remove_parts_along(Z, V, mass)
    lam_y, C = _ritz_in_span(K, mass, V, k - d)
    seconds["inverse_iteration"] = time.perf_counter() - t
    if V.shape[1] >= d + C.shape[1]:
        transform_columns_in_place(V, C, lead=d)  # [Z, V C] at the start of V's memory
        V.resize((n, d + C.shape[1]), refcheck=False)  # the guard columns' memory freed
        U = V
    else:  # fewer carried modes than wanted (a small copy, many components)
        U = np.empty((n, d + C.shape[1]))
        for rows in _rows(n):
            U[rows, d:] = V[rows] @ C
    del V
    U[:, :d] = Z
    del Z
    lam = np.concatenate([np.zeros(d), lam_y])
    info = {
        "coarse_vertices": int(coarse.mesh.n_vertices),
        "coarse_modes": int(lam_c.shape[0]),
        "null_space_dimension": int(d),
        "seconds": {s: round(v, 4) for s, v in seconds.items()},
    }
    return lam, U, solver, info


ESTIMATE_BLOCK_COLUMNS = 16
"""Columns per block of the coarse start's estimate: each block's residuals and
solutions take 20 bytes an entry (float32 residuals, the double-precision solver's copy
and solution), 180 MB at 16 columns of the cow Loop x3's 557k unknowns; narrower blocks
cost time there (a solve of 8 columns takes 1.5 times as long a column as one of 16)."""

SCALAR_ESTIMATE_BLOCK_COLUMNS = 8
"""Columns per block of the scalar operators' estimate (Laplacian, E_D^N, the normal
shells) and of their refinement's solves.  PARDISO's work arrays for a solve grow with
its columns, about 6 further (N,) float64 arrays a column, and beside the factor and the
modes they decide the preview's peak: the hand Loop x2's Laplacian fast preview peaks at
815 MB with blocks of 16 and 719 MB with blocks of 8 (the exact solve: 764 MB), 4 %
slower; the cow Loop x3's refined Laplacian, whose space holds the guard modes beside
the wanted ones, at 694 MB with blocks of 16 and 640 MB with blocks of 8 (the exact
solve: 689 MB), 0.7 s slower of 12."""


def _factor_estimate(
    K, mass, solver, lam, U, lam_scale, d, block_columns=ESTIMATE_BLOCK_COLUMNS, above=np.inf
):
    """(relative residuals, estimated errors, how they were estimated) of the pairs
    (lam, U) whose first d are exact null vectors: each non-zero mode's estimate comes
    from its residual r solved with ``solver`` (a :class:`ShiftedFactor` of
    ``K + s M``, s below the spectrum), ``r^T S r`` and ``|S r|_M``
    (:func:`_first_order_errors`).  On the coarse start's pairs of the cow and homer
    Loop x2 (3D shells, 100 modes) it reads 0.99 and 1.0 times the true errors (median
    over the modes; 0.52 to 1.9 times each), where ``r^T S r / lam`` alone read 0.73
    and 0.78 times (0.30 at the least) and the block-Jacobi estimate 0.22 times.
    Columns go through the solve in blocks of
    ``block_columns`` (:data:`ESTIMATE_BLOCK_COLUMNS`, for the scalar operators
    :data:`SCALAR_ESTIMATE_BLOCK_COLUMNS`), so the estimate's arrays stay small beside
    the factor and the modes.  ``above``: see :func:`_first_order_errors`."""
    c = lam.shape[0]
    res, est = np.zeros(c), np.zeros(c)
    if d:
        res[:d] = _zero_mode_residuals(K, mass, lam, U, d, lam_scale)
    if d < c:
        relative, _, energies, norms = _preconditioned_residuals(
            K, mass, solver, lam, U, lam_scale, slice(d, c), None, False, block_columns
        )
        res[d:] = relative
        est[d:] = _first_order_errors(lam[d:], solver.shift, energies, norms, above)
    method = "factor of the operator shifted below its spectrum"
    if np.isfinite(above):
        method += ", errors in the modes above the refined space's"
    return res, est, {"method": method}


def _coarse_preview(mesh, operator, K, mass, k, coarse, weights, report, refine, settings, nulls):
    """:func:`preview_spectrum` from a coarse copy (:func:`_coarse_start`), its estimate
    and, where that of the lower half of the non-zero modes is above the threshold and
    ``refine`` is set, subspace steps with the start's factor; None where the start
    fails."""
    t = time.perf_counter()
    started = _coarse_start(mesh, operator, K, mass, k, coarse, weights, report, nulls)
    if started is None:
        return None
    lam, U, solver, start_info = started
    seconds = {"start": time.perf_counter() - t}
    lam_scale = typical_eigenvalue(K, mass)
    d = start_info["null_space_dimension"]
    t = time.perf_counter()
    report("preview: estimating errors", 0.8)
    res, est, estimate = _factor_estimate(K, mass, solver, lam, U, lam_scale, d)
    seconds["estimate"] = time.perf_counter() - t
    refine_above = REFINE_ABOVE if settings.refine_above is None else settings.refine_above
    steps = REFINE_STEPS if settings.refine_steps is None else settings.refine_steps
    refinement = {"steps": 0, "estimated_error_before": float(est.max(initial=0.0))}
    # the lower half decides: the carried modes' top pairs are the least accurate, their
    # own estimates say so, and two subspace steps for them would cost as much as the
    # exact solve (the cow Loop x3: 25 s of its 58)
    lower = est[d:][: lowest_share(lam.shape[0] - d, 0.5)]
    if refine and lower.max(initial=0.0) > refine_above:
        t = time.perf_counter()
        c = lam.shape[0]
        buffer = _refinement_buffer(U, steps, K.shape[0])
        del U
        lam, above = _refine(K, mass, solver, lam, buffer, c, steps, report, 0.9)
        refinement["steps"] = steps
        U = buffer
        del buffer
        res, est, estimate = _factor_estimate(K, mass, solver, lam, U, lam_scale, d, above=above)
        seconds["refinement"] = time.perf_counter() - t
    del solver
    info = {
        "samples": 0,
        "null_space_dimension": d,
        "null_space": nulls.summary() if d else "",
        "coarse_start": start_info,
        "refinement": refinement,
        "reduced_dimension": int(start_info["coarse_modes"]),
        "smoothing": False,
        "seconds_by_stage": {s: round(v, 4) for s, v in seconds.items()},
        "galerkin_eigenvalues": [],
        "estimated_errors": [float(e) for e in est],
        "estimated_error": float(est.max(initial=0.0)),
        "correction": "coarse copy's modes, one inverse-iteration step",
        "estimate": estimate,
    }
    return lam, U, res, info


def preview_spectrum(
    mesh: Mesh,
    operator: str,
    K: sp.spmatrix,
    mass: np.ndarray,
    k: int,
    samples: int | None = None,
    radius_factor: float | None = None,
    enrich: int | None = None,
    smoothing: bool | None = None,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    refine: bool | None = None,
    coarse: CoarseCopy | Future | None = None,
    weights: tuple[float, float] = (1.0, 1.0),
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """Preview eigenpairs of ``K x = lambda diag(mass) x`` for ``operator`` on ``mesh``.

    For the 3D shells with a ``coarse`` copy of the mesh (``weights``: the bending and
    membrane weights K was made with) the preview starts from the copy's own modes
    (:func:`_coarse_start`) and is refined by subspace steps with the same factor where
    the estimate of its lower half of modes calls for it; where that start fails, and
    otherwise:

    Galerkin projection onto :func:`reduced_basis` (``samples`` centres, polynomial
    degree ``enrich`` and ``radius_factor``; the defaults per operator are in
    :data:`SPACE_SETTINGS`), then (``smoothing``, by default for the two Discrete Shells
    operators) Rayleigh-Ritz in the reduced space together with the block-Jacobi
    preconditioned residuals of the Galerkin modes (:func:`_two_level_step`), which adds
    the mesh-scale components a smooth space lacks.

    For the 3D shells (``factor_step`` of :data:`SPACE_SETTINGS`) the Galerkin pairs are
    corrected by :func:`_factor_steps` instead, where its single-precision factor fits
    the memory limit; a second step (``refine``) where its estimate is above the
    threshold below.  Otherwise:

    The estimated errors come from the residuals of the final pairs (see
    :func:`estimated_errors`); the operators without the 3D shells' correction step
    (the Laplacian, E_D^N and the normal shells) factorise the operator shifted below
    its spectrum and estimate with that factor (:func:`_factor_estimate`), which a
    refinement then reuses: block-Jacobi conjugate gradients read a localised Laplacian
    mode of Cheburashka Loop x2 at 2.4 % where it was 19 % off, the factor at 19.1 %.
    A fast preview (``refine`` False) whose factor would go out of core keeps the
    block-Jacobi estimate.  Where the largest is above the
    operator's threshold (``refine_above`` of :data:`SPACE_SETTINGS`, by default
    :data:`REFINE_ABOVE`: curved meshes with thin parts, creases) and ``refine`` is set
    (default: per operator, see
    :data:`SPACE_SETTINGS`), ``refine_steps`` (by default :data:`REFINE_STEPS`) steps of
    subspace iteration with a factorisation of the fine operator follow
    (:func:`_subspace_step`), and the estimate is made again.

    The smooth space's pairs carry :data:`SMOOTH_GUARD` guard modes above the k asked
    for through the correction and the refinement; the lowest k are returned.

    Returns (eigenvalues (k,), modes (N, k) Mass-orthonormal, residuals (k,), info) where
    info holds the reduced space's size, timings and ``estimated_errors``.
    """

    def report(stage: str, fraction: float) -> None:
        if cancel is not None and cancel():
            raise Cancelled()
        if progress is not None:
            progress(stage, fraction)

    K = sp.csr_matrix(K)
    mass = np.asarray(mass, dtype=np.float64)
    seconds = {}
    t = time.perf_counter()
    settings = operator_info(operator).preview
    if smoothing is None:
        smoothing = settings.smoothing
    if refine is None:
        refine = settings.refine
    if samples is None:
        samples = settings.samples(k)
    enrich = settings.degree if enrich is None else int(enrich)
    if radius_factor is None:
        radius_factor = settings.radius_factor
    nulls = None
    if coarse is not None and settings.factor_step:
        nulls = null_space(mesh, operator, K, mass)  # while a copy still being made is made
        with blas_limit():
            done = _coarse_preview(
                mesh, operator, K, mass, k, coarse, weights, report, refine, settings, nulls
            )
        if done is not None:
            return done
    report("preview: sampling", 0.05)
    samples = max(1, min(int(samples), max_samples(mesh.n_vertices, enrich)))
    candidates = mesh.n_vertices if settings.exact_sampling else None
    basis = reduced_basis(mesh, operator, samples, radius_factor, enrich, candidates=candidates)
    info = basis.info
    seconds["basis"] = time.perf_counter() - t
    t = time.perf_counter()
    report("preview: projecting", 0.2)
    Kr = _project(K, basis)
    Mr = _project_mass(mass, basis)
    E = _null_space_complement(mesh, operator, K, mass, basis, Mr, nulls)
    if E is not None:  # exact null vectors the space lacks (components, rotations)
        Kr, Mr = _extend(Kr, K, basis, E), _extend(Mr, sp.diags(mass), basis, E)
        basis = basis.with_dense(E)
    info["null_space_columns_added"] = 0 if E is None else int(E.shape[1])
    seconds["projection"] = time.perf_counter() - t
    t = time.perf_counter()
    dim = Kr.shape[0]
    # guard modes above the k wanted (see SMOOTH_GUARD)
    wanted = min(k, dim)
    k_eff = min(wanted + _guard_modes(k), dim)
    report("preview: reduced eigenproblem", 0.45)
    lam, Y = _solve_reduced(Kr, Mr, k_eff)
    seconds["reduced_solve"] = time.perf_counter() - t
    t = time.perf_counter()
    report("preview: prolonging", 0.65)
    U = basis.prolong(Y)
    seconds["prolongation"] = time.perf_counter() - t
    lam_scale = typical_eigenvalue(K, mass)
    galerkin = lam
    refine_above = REFINE_ABOVE if settings.refine_above is None else settings.refine_above
    steps = REFINE_STEPS if settings.refine_steps is None else settings.refine_steps
    corrected = None
    # the reduced space, held here so that the correction step can let it go once its
    # factor exists (the two-level step needs it where that factor does not fit)
    space = {"basis": basis, "Kr": Kr, "Mr": Mr}
    del basis, Kr, Mr
    if settings.factor_step:
        t = time.perf_counter()
        with blas_limit():
            corrected = _factor_steps(
                K,
                mass,
                lam,
                U,
                lam_scale,
                refine_above,
                STEP_REFINE_STEPS if refine else 0,
                report,
                factored=space.clear,
                give_up=refine,
                wanted=wanted,
            )
        if corrected is not None:
            lam, res, est, step_info = corrected
            seconds["correction"] = time.perf_counter() - t
            info["factor_step"] = step_info
            smoothing = False
    # the step's estimate stands unless the block-Jacobi one below replaces it
    estimate = {"method": "single-precision factor"}
    converged = corrected is not None and not step_info["unconverged"]
    if not converged:
        precondition = _jacobi_blocks(K, operator_info(operator).unknowns_per_vertex)
    if smoothing:
        t = time.perf_counter()
        report("preview: smoothing", 0.8)
        lam, U = _two_level_step(
            K, mass, space["basis"], space["Kr"], space["Mr"], lam, U, precondition
        )
        seconds["smoothing"] = time.perf_counter() - t
    space.clear()  # the reduced space is done with: its memory for what follows

    solver = None
    if corrected is None:
        t = time.perf_counter()
        report("preview: estimating errors", 0.9)
        if not settings.factor_step:  # the refinement's factor, if one follows, decides it
            solver = _factor_below(K, mass, lam, lam_scale)
            if solver is not None and solver.out_of_core and not refine:
                solver = None  # solves from a file would cost more than the preview
        if solver is not None:  # the wanted modes' estimate (not the guards')
            d = _leading_zero_modes(lam, lam_scale)
            res, est, estimate = _factor_estimate(
                K, mass, solver, lam[:wanted], U, lam_scale, d, SCALAR_ESTIMATE_BLOCK_COLUMNS
            )
        else:
            res, est, estimate = _block_jacobi_estimate(
                K, mass, lam[:wanted], np.ascontiguousarray(U[:, :wanted]), lam_scale, precondition
            )
        seconds["estimate"] = time.perf_counter() - t
    if converged:  # its further steps are the refinement
        refinement = {
            "steps": step_info["steps"] - 1,
            "estimated_error_before": step_info["estimated_error_first_step"],
        }
    else:  # modes missing after the step (unconverged), or no step taken
        refinement = {"steps": 0, "estimated_error_before": float(est.max(initial=0.0))}
    if not converged and refine and est[:wanted].max(initial=0.0) > refine_above:
        t = time.perf_counter()
        report("preview: refining (factorising)", 0.92)
        c = wanted  # the guard modes stay in the refinement's space, never solved for
        # the buffer before a factor made here, so that the factor reuses the memory of
        # the U it replaces
        buffer = _refinement_buffer(U, steps, K.shape[0], wanted)
        del U
        if solver is None:
            solver = _factor_below(K, mass, lam, lam_scale)
        if solver is None:  # keep the preview as it is
            refinement["failed"] = "the operator could not be factorised below its spectrum"
        taken = steps if solver is not None else 0
        narrow = None if settings.factor_step else SCALAR_ESTIMATE_BLOCK_COLUMNS
        lam, above = _refine(K, mass, solver, lam, buffer, c, taken, report, 0.94, narrow)
        U = buffer
        del buffer
        refinement["steps"] += taken
        refinement["factor_out_of_core"] = bool(solver is not None and solver.out_of_core)
        # after the steps the errors lie in the modes just above the refined space, which
        # the residuals through the factor read with the space's reference value
        # (block-Jacobi read 0.13 to 0.26 times the error there)
        if taken:
            report("preview: estimating errors", 0.98)
            d = _leading_zero_modes(lam, lam_scale)
            columns = (
                ESTIMATE_BLOCK_COLUMNS if settings.factor_step else SCALAR_ESTIMATE_BLOCK_COLUMNS
            )
            res, est, estimate = _factor_estimate(
                K, mass, solver, lam, U, lam_scale, d, columns, above=above
            )
        solver = None
        seconds["refinement"] = time.perf_counter() - t
    del solver
    lam, U = _first_modes(lam, U, wanted)
    res, est, galerkin = res[:wanted], est[:wanted], galerkin[:wanted]
    d, nulls = _with_exact_null_vectors(mesh, operator, K, mass, lam, U, res, lam_scale, nulls)
    info.update(
        null_space_dimension=d,
        null_space=nulls.summary() if d else "",
        refinement=refinement,
        reduced_dimension=int(dim),
        smoothing=bool(smoothing),
        seconds_by_stage={s: round(v, 4) for s, v in seconds.items()},
        galerkin_eigenvalues=[float(x) for x in galerkin],
        estimated_errors=[float(e) for e in est],
        estimated_error=float(est.max()),
        correction=(
            "single-precision factor step"
            if corrected is not None
            else ("two-level step" if smoothing else "none")
        ),
        estimate=estimate,
    )
    return lam, U, res, info


SMOOTH_GUARD = 0.25
"""The smooth-space preview takes this share more Galerkin modes than are asked for (at
least :data:`REFINE_GUARD_MIN`), keeps them through its correction and refinement, and
returns the lowest k.  Without them the top modes' errors lie in the modes just above
them, outside the space, where the residual estimate reads them short: spot Loop x2's
3D shells refined preview, 100 modes, estimated its largest error at 0.66 % where mode
99 was 6.2 % off (with them: 3.6 % off, estimated 4.3 %); spot Loop x1's refined
Laplacian and E_D^N read 0.13 and 0.17 times their largest errors (with them and the
estimate's reading above the refined space, :func:`_first_order_errors`: 2.1 and 2.5
times, each mode's at least its error, and the errors themselves halved).  The guard
modes stay in the spaces unsolved: only the wanted modes' residuals are preconditioned
and estimated (solving the 3D shells' guard modes too took them to 1.37 %, estimated
1.41 %, for a quarter more time and 0.5 GB more at the part flat x3's peak)."""


def _guard_modes(k: int) -> int:
    return max(REFINE_GUARD_MIN, int(np.ceil(SMOOTH_GUARD * k)))


def _first_modes(lam: np.ndarray, U: np.ndarray, count: int):
    """(lam, U) cut to their first ``count`` pairs, U in its own memory (no copy)."""
    if lam.shape[0] <= count:
        return lam, U
    if U.flags.c_contiguous and U.flags.owndata:
        transform_columns_in_place(U, count)
        U.resize((U.shape[0], count), refcheck=False)
    else:
        U = np.ascontiguousarray(U[:, :count])
    return lam[:count], U


def preview_possible(mesh: Mesh, operator: str, k: int) -> bool:
    """Whether ``mesh`` holds a reduced space of at least 3 k functions for ``operator``
    (:func:`max_samples`); smaller meshes get the exact spectrum, quick there."""
    return preview_possible_on(mesh.n_vertices, operator, k)


def preview_possible_on(n_vertices: int, operator: str, k: int) -> bool:
    """:func:`preview_possible` for a mesh of ``n_vertices``."""
    info = operator_info(operator)
    degree = info.preview.degree
    functions = max_samples(n_vertices, degree) * scalar_functions_per_sample(degree)
    return functions * info.unknowns_per_vertex >= 3 * int(k)


def compute_preview(
    mesh: Mesh,
    operator: str,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    samples: int | None = None,
    refine: bool | None = None,
    coarse: CoarseCopy | Future | None = None,
) -> Spectrum:
    """``compute_spectrum(..., accuracy="preview")``: a :class:`Spectrum` whose
    ``parameters["preview"]`` holds the reduced space, timings and estimated errors
    (``spec.is_preview``, ``spec.estimated_error``).

    For meshes where :func:`preview_possible` holds; ``compute_spectrum`` computes the
    exact spectrum of the others.  ``refine``: as in :func:`preview_spectrum` (False:
    ``accuracy="fast preview"``); ``coarse``: the 3D shells' coarse copy to start from
    (see :func:`preview_spectrum`)."""
    per_vertex = operator_info(operator).unknowns_per_vertex
    started = time.perf_counter()
    if cancel is not None and cancel():
        raise Cancelled()
    if progress is not None:
        progress("assembling", 0.0)
    K, mass = operator_matrices(mesh, operator, bending, membrane)
    assembled = time.perf_counter()
    k = min(int(k), K.shape[0])
    lam, U, res, info = preview_spectrum(
        mesh,
        operator,
        K,
        mass,
        k,
        samples=samples,
        progress=progress,
        cancel=cancel,
        refine=refine,
        coarse=coarse,
        weights=(bending, membrane),
    )
    n = mesh.n_vertices
    modes = np.ascontiguousarray(U)
    if per_vertex > 1:
        modes = modes.reshape(n, per_vertex, -1)
    if progress is not None:
        progress("done", 1.0)
    return Spectrum(
        eigenvalues=lam,
        modes=modes,
        operator=operator,
        mass=mass[::per_vertex],
        residuals=res,
        mesh_hash=mesh.hash,
        parameters={
            "k": int(lam.shape[0]),
            "bending": float(bending),
            "membrane": float(membrane),
            "method": (
                "preview: Rayleigh-Ritz in a reduced space of smooth functions"
                if "coarse_start" not in info
                else "preview: a coarse copy's modes, one inverse-iteration step"
            ),
            "zero_mode_scale": typical_eigenvalue(K, mass),
            "null_space_dimension": int(info["null_space_dimension"]),
            "n_components": int(mesh.n_components),
            **({"null_space": info["null_space"]} if info["null_space"] else {}),
            "seconds_assembly": assembled - started,
            "seconds_total": time.perf_counter() - started,
            "preview": info,
        },
    )
