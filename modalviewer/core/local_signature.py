"""Signatures at chosen vertices without a truncated spectrum (paper Section 6, Lemma 2).

The signature of :func:`.signatures.signature`,
``S_t(v) = sum_j exp(-lambda_j t) |phi_j(v)|^2`` over *all* modes (M-orthonormal
``phi_j``), is the diagonal of the kernel of the linearised gradient flow (eq. 26):
for each unknown ``r`` of vertex ``v`` (one for the scalar energies, three for the 3D
shells, the sum over alpha of Lemma 2),

    S_t(v) = sum_r  e_r^T M^-1/2 exp(-t M^-1/2 K M^-1/2) M^-1/2 e_r,

a quadratic form of the matrix exponential.  It is evaluated by Lanczos quadrature
(Golub and Meurant): ``m`` Lanczos steps on ``A = M^-1/2 K M^-1/2`` started at ``e_r``
give the Gauss rule ``|b|^2 [exp(-t T_m)]_11`` for every ``t`` at once, exact as ``m``
grows and accurate to rounding once ``m`` exceeds about ``sqrt(t lambda_max)``.  Small
scales, where a truncated spectrum misses the most, need the fewest steps.  The steps
stop when every requested scale has settled to ``rtol``.

Zero modes are left out (as by default in :func:`.signatures.signature`) by starting
from ``b = P e_r``, where ``P`` projects out the operator's exactly known null vectors
(:mod:`.nullspace`); ``P`` commutes with ``A``, so ``b^T exp(-tA) b`` is the sum over
the other modes.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .mesh import Mesh
from .nullspace import null_space
from .operators import operator_info
from .pipeline import operator_matrices
from .validate import check_times, check_vertices

__all__ = ["local_signature"]


def _quadrature(A, b: np.ndarray, times: np.ndarray, rtol: float, max_steps: int) -> np.ndarray:
    """(T,) ``b^T exp(-t A) b`` for each t by Lanczos quadrature (no reorthogonalisation:
    the Gauss rule of finite-precision Lanczos still converges to the quadratic form)."""
    beta0 = float(np.linalg.norm(b))
    if beta0 <= 1e-10:  # e_r lies in the null space to rounding: b^T exp(-tA) b <= |b|^2
        return np.zeros(len(times))
    q_prev = np.zeros_like(b)
    q = b / beta0
    alphas: list[float] = []
    betas: list[float] = []
    previous = None
    settled = 0
    next_check = 8  # checks grow apart with the step count: the rule costs O(m^2) each
    for step in range(1, max_steps + 1):
        w = A @ q
        alpha = float(q @ w)
        w -= alpha * q
        if betas:
            w -= betas[-1] * q_prev
        beta = float(np.linalg.norm(w))
        alphas.append(alpha)
        breakdown = beta <= 1e-14 * max(abs(alpha), 1.0)
        if step >= next_check or breakdown or step == max_steps:
            next_check = step + max(8, step // 8)
            theta, s = sla.eigh_tridiagonal(np.array(alphas), np.array(betas))
            weights = s[0] ** 2
            values = beta0**2 * (np.exp(-np.outer(times, np.maximum(theta, 0.0))) @ weights)
            if breakdown:  # an invariant subspace: the rule is exact
                return values
            # values below rounding of |b|^2 (an unknown almost inside the null space)
            # settle in absolute terms: the quadratic form is at most |b|^2
            noise = 1e-13 * beta0**2
            if previous is not None and np.all(
                np.abs(values - previous) <= rtol * np.abs(values) + noise
            ):
                settled += 1
                if settled == 2:
                    return values
            else:
                settled = 0
            previous = values
        betas.append(beta)
        q_prev, q = q, w / beta
    raise RuntimeError(
        f"the Lanczos quadrature did not settle to {rtol:g} in {max_steps} steps; "
        "raise max_steps or use a smaller largest scale"
    )


def local_signature(
    mesh: Mesh,
    operator: str,
    vertices,
    times,
    include_zero: bool = False,
    bending: float = 1.0,
    membrane: float = 1.0,
    rtol: float = 1e-10,
    max_steps: int = 20000,
) -> np.ndarray:
    """The signature at ``vertices`` and scales ``times``, summed over all modes.

    The same quantity as ``signature(compute_spectrum(mesh, operator, k=all), times,
    include_zero, vertices)[1]`` (heat kernel signature for ``"laplacian"``, feature
    signature for ``"modified_dirichlet"``, vibration signature for ``"shells"``), with no
    truncation error, computed without any eigenvectors (Lemma 2 of the paper).

    Parameters
    ----------
    mesh : the surface.
    operator : one of ``OPERATORS``.
    vertices : int or sequence of vertex indices (0-based).
    times : (T,) positive scales.
    include_zero : add the zero modes (constants, rigid motions) as ``signature`` does.
    bending, membrane : Discrete Shells weights.
    rtol : relative accuracy at which each scale's value is accepted.
    max_steps : Lanczos steps allowed per unknown; the cost grows with
        ``sqrt(max(times) * lambda_max)``.

    Returns
    -------
    (len(vertices), T) array; a single vertex gives (1, T).

    Raises
    ------
    TypeError, IndexError, ValueError
        For vertex indices that are not integers or out of range, and scales that are
        not positive and finite (:mod:`.validate`).
    RuntimeError
        If a scale has not settled to ``rtol`` within ``max_steps`` Lanczos steps.
    """
    vertices = check_vertices(vertices, mesh.n_vertices)
    times = check_times(times)
    K, mass = operator_matrices(mesh, operator, bending, membrane)
    per_vertex = operator_info(operator).unknowns_per_vertex
    inv_sqrt = 1.0 / np.sqrt(mass)
    A = sp.csr_matrix(sp.diags(inv_sqrt) @ K @ sp.diags(inv_sqrt))
    Y = None
    if not include_zero:
        Z = null_space(mesh, operator, K, mass).vectors
        if Z.shape[1]:
            Y = sp.csr_matrix(sp.diags(np.sqrt(mass)) @ Z)  # orthonormal columns
    out = np.zeros((len(vertices), len(times)))
    N = K.shape[0]
    for i, v in enumerate(vertices):
        for alpha in range(per_vertex):
            r = int(v) * per_vertex + alpha
            b = np.zeros(N)
            b[r] = 1.0
            if Y is not None:
                b -= Y @ (Y[r].toarray().ravel())
            out[i] += _quadrature(A, b, times, rtol, max_steps) / mass[r]
    return out
