"""Signatures at chosen vertices without a truncated spectrum (paper Section 6, Lemma 2).

The signature over *all* modes, ``S_t(v) = sum_j exp(-lambda_j t) |phi_j(v)|^2``, is
the diagonal of the kernel of the linearised gradient flow (eq. 26): summed over the
unknowns ``r`` of vertex ``v`` (three for the 3D shells),
``S_t(v) = sum_r e_r^T M^-1/2 exp(-t M^-1/2 K M^-1/2) M^-1/2 e_r``, each quadratic form
by Lanczos quadrature (Golub and Meurant) on the shifted inverse of ``A = M^-1/2 K M^-1/2``
(van den Eshof and Hochbruck): one factorisation of ``K + sigma M``, then Lanczos steps
from ``e_r`` give the Gauss rule for every ``t`` at once.  Zero modes are left out by
starting from ``P e_r``, ``P`` projecting out the known null vectors (:mod:`.nullspace`),
which commutes with ``A``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .assembly import operator_matrices
from .factor import SPDSolver
from .mesh import Mesh
from .nullspace import null_space
from .operators import OperatorLike, operator_info
from .spectrum import Spectrum, on_solver_mesh
from .validate import check_times, check_vertices


def _quadrature(
    B: Callable[[np.ndarray], np.ndarray],
    sigma: float,
    b: np.ndarray,
    times: np.ndarray,
    rtol: float,
    max_steps: int,
    known: np.ndarray,
) -> np.ndarray:
    """(T,) ``b^T exp(-t A) b`` for each t by Lanczos quadrature on the shifted inverse
    ``B``, whose Ritz values ``mu`` stand for ``x = 1/mu - sigma`` of ``A``, so the steps
    needed do not grow with the stiffest mode (huge for the 3D shells' small triangles).
    No reorthogonalisation: finite-precision Lanczos' Gauss rule still converges.  A
    value has settled when it changes by less than ``rtol`` of itself plus ``known`` (the
    part already summed from a spectrum)."""
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
        w = B(q)
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
            x = 1.0 / np.maximum(theta, np.finfo(float).tiny) - sigma
            values = beta0**2 * (np.exp(-np.outer(times, np.maximum(x, 0.0))) @ weights)
            if breakdown:  # an invariant subspace: the rule is exact
                return values
            # values below rounding of |b|^2 (an unknown almost inside the null space)
            # settle in absolute terms: the quadratic form is at most |b|^2
            noise = 1e-13 * beta0**2
            if previous is not None and np.all(
                np.abs(values - previous) <= rtol * (np.abs(values) + known) + noise
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
    operator: OperatorLike,
    vertices,
    times,
    include_zero: bool = False,
    bending: float = 1.0,
    membrane: float = 1.0,
    rtol: float = 1e-10,
    max_steps: int = 2000,
    spectrum: Spectrum | None = None,
) -> np.ndarray:
    """(len(vertices), T) the signature at ``vertices`` and scales ``times`` summed over
    all modes: ``signature(compute_spectrum(mesh, operator, k=all), times, include_zero,
    vertices)[1]`` with no truncation error and no eigenvectors (Lemma 2).

    Each scale's value is accepted at relative accuracy ``rtol``; a RuntimeError if it
    has not settled within ``max_steps`` Lanczos steps per unknown.  With ``spectrum``,
    an exact spectrum of the same mesh and operator, its modes are summed directly and
    the quadrature adds only the modes above them, so large scales cost a few steps
    (without one, scales far above ``4 ln 10 / lambda_1`` on fine meshes can need
    thousands).
    """
    operator = operator_info(operator)
    vertices = check_vertices(vertices, mesh.n_vertices)
    solver = mesh.solver_mesh
    if solver is not mesh:  # unused or merged vertices: on the vertices faces use
        picks = [solver.mesh_vertex(v) for v in vertices]  # an unused vertex: its name
        spectrum = None if spectrum is None else on_solver_mesh(spectrum, solver)
        args = (include_zero, bending, membrane, rtol, max_steps, spectrum)
        return local_signature(solver, operator, picks, times, *args)
    times = check_times(times)
    K, mass = operator_matrices(mesh, operator, bending, membrane)
    per_vertex = operator.unknowns_per_vertex
    # B = (A + sigma I)^-1 = M^1/2 (K + sigma M)^-1 M^1/2 from one factorisation, sigma
    # the scales' geometric mean's rate, where exp(-t x) varies the most
    sigma = 1.0 / float(np.sqrt(times.min() * times.max()))
    shifted = SPDSolver(sp.csr_matrix(K + sigma * sp.diags(mass)))
    root = np.sqrt(mass)

    def B(v: np.ndarray) -> np.ndarray:
        return root * shifted.solve(root * v)

    T = len(times)
    known = np.zeros((len(vertices), per_vertex, T))
    if spectrum is not None:
        if spectrum.operator != operator.name or spectrum.mesh_hash != mesh.hash:
            raise ValueError("spectrum must be of this mesh and operator")
        modes = spectrum.modes.reshape(K.shape[0], spectrum.k)
        used = np.ones(spectrum.k, dtype=bool) if include_zero else ~spectrum.zero_mode_mask()
        rows = (vertices[:, None] * per_vertex + np.arange(per_vertex)).ravel()
        weights = np.exp(-np.outer(np.maximum(spectrum.eigenvalues[used], 0.0), times))
        known = ((modes[rows][:, used] ** 2) @ weights).reshape(len(vertices), per_vertex, T)
        # the quadrature's start vectors leave out every mode of the spectrum
        Y = np.sqrt(mass)[:, None] * modes
    elif not include_zero:
        Z = null_space(mesh, operator, K, mass).vectors
        Y = (sp.diags(np.sqrt(mass)) @ Z).toarray() if Z.shape[1] else None  # orthonormal
    else:
        Y = None
    out = np.zeros((len(vertices), T))
    N = K.shape[0]
    for i, v in enumerate(vertices):
        for alpha in range(per_vertex):
            r = int(v) * per_vertex + alpha
            b = np.zeros(N)
            b[r] = 1.0
            if Y is not None:
                b -= Y @ Y[r]
            scaled_known = known[i, alpha] * mass[r]
            tail = _quadrature(B, sigma, b, times, rtol, max_steps, scaled_known)
            out[i] += known[i, alpha] + tail / mass[r]
    return out
