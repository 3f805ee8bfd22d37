"""A spectrum-slicing eigensolver (Vallet and Levy 2008), built from the library's parts
to measure whether slicing pays; :mod:`benchmarks.slicing` runs it against the solver.

The lowest k pairs of ``K x = lambda M x`` (M diagonal) in B bands of about k / B pairs:

1. the first band is the library's own solve (:func:`.eigen.solve_lowest`: shift below
   the spectrum, Cholesky factor, the known null vectors deflated);
2. each further band places a shift ``sigma`` above the highest eigenvalue found so far,
   at the distance that, by the last band's density of eigenvalues, puts about a
   quarter of the band's pairs below that eigenvalue (the overlap); factors
   ``K - sigma M`` (indefinite: PARDISO's symmetric indefinite LDL^T, mtype -2,
   which also gives the inertia); runs the same
   block Krylov-Schur iteration on ``M^1/2 (K - sigma M)^-1 M^1/2`` for the pairs
   nearest sigma (largest ``|theta|``); refines them as the solver does (one block step
   of inverse iteration, Rayleigh-Ritz with K); and keeps the new ones.

The pairs nearest sigma fill an interval ``(sigma - r, sigma + r)``: all eigenvalues in
it are found.  A band is accepted only if that interval reaches below the highest
eigenvalue found before (no gap), and the factor's inertia (the number of eigenvalues
below sigma, Sylvester) equals the number found below sigma.  Pairs are not deflated
across bands: the duplicates below the previous top are dropped.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from modalviewer.core import krylov
from modalviewer.core.eigen import _rayleigh_ritz_in_place, solve_lowest
from modalviewer.core.factor import _load_mkl, _Pardiso
from modalviewer.core.krylov import StageTimer, block_krylov_schur
from modalviewer.core.memory import krylov_sizes

BELOW_SHARE = 0.25
"""Share of a band's pairs expected below the previous band's top (the overlap)."""


MARGIN = 1.1
"""A band asks for this many times the pairs it should add (the density is estimated)."""


class IndefinitePardiso(_Pardiso):
    """PARDISO's real symmetric indefinite factorisation (Bunch-Kaufman pivoting)."""

    MTYPE = -2

    @property
    def inertia(self) -> tuple[int, int]:
        """(positive, negative) eigenvalues of the factored matrix."""
        return int(self._iparm[21]), int(self._iparm[22])


def _nearest_ritz_pairs(T, R, j: int, wanted: int, keep: int, tol: float):
    """:func:`.krylov._ritz_pairs` ordered by ``|theta|`` (an indefinite operator)."""
    theta, S = np.linalg.eigh(0.5 * (T[:j, :j] + T[:j, :j].T))
    order = np.argsort(-np.abs(theta))
    theta, S = theta[order], S[:, order]
    estimates = np.linalg.norm(R @ S[:, : min(keep, j)], axis=0)
    floor = 16 * np.finfo(float).eps * abs(theta[0])
    converged = estimates[:wanted] <= np.maximum(tol * np.abs(theta[:wanted]), floor)
    done = int(np.argmin(converged)) if not converged.all() else wanted
    return theta, S, estimates, done


class SliceGap(RuntimeError):
    """A band did not reach down to the eigenvalues found before it."""


def sliced_lowest(K, mass: np.ndarray, k: int, bands: int, null_space=None, tol=1e-10):
    """(eigenvalues (k,), Mass-orthonormal modes (N, k), stage seconds, operator columns,
    one dict per band: shift, pairs, operator columns, stage seconds, and for the bands
    after the first the inertia check) of the k lowest pairs in ``bands`` bands."""
    N = K.shape[0]
    timer = StageTimer()
    sqrt_m = np.sqrt(mass)
    inv_sqrt_m = 1.0 / sqrt_m
    per_band = int(np.ceil(k / bands))
    first = solve_lowest(K, mass, min(per_band, k), null_space=null_space, tol=tol)
    for stage, seconds in first.stage_seconds.items():
        timer.seconds[stage] = timer.seconds.get(stage, 0.0) + seconds
    columns = first.operator_columns
    lam_parts, X_parts = [first.eigenvalues], [first.vectors]
    found = first.eigenvalues.shape[0]
    last_band = first.eigenvalues[first.null_dim :]
    checks = [
        {
            "sigma": first.shift,
            "pairs": int(first.eigenvalues.shape[0]),
            "columns": int(first.operator_columns),
            "stages": dict(first.stage_seconds),
        }
    ]
    lib = _load_mkl()
    while found < k:
        before = dict(timer.seconds)
        new = min(per_band, k - found)
        top = lam_parts[-1][-1]
        # the density near the top: the last band's upper half (eigenvalues spread out
        # as they grow, like i^2 for bending)
        upper = last_band[last_band.shape[0] // 2 :]
        density = (upper.shape[0] - 1) / (upper[-1] - upper[0])
        wanted = int(np.ceil(MARGIN * new / (1.0 - BELOW_SHARE)))
        # the band's pairs spread over about wanted / density around sigma; a share
        # BELOW_SHARE of them lie below the previous top
        sigma = top + (0.5 - BELOW_SHARE) * wanted / density
        with timer("factorisation"):
            A = (K - sp.diags(sigma * mass)).tocsr()
            factor = IndefinitePardiso(A, lib)
        negative = factor.inertia[1]

        def apply_op(V, factor=factor):
            return sqrt_m[:, None] * factor.solve(sqrt_m[:, None] * V)

        k_work, block, max_basis, keep = krylov_sizes(wanted, N)
        ordinary = krylov._ritz_pairs
        krylov._ritz_pairs = _nearest_ritz_pairs
        try:
            theta, Y, band_columns = block_krylov_schur(
                apply_op, N, wanted, keep=keep, block=block, max_basis=max_basis, tol=tol,
                report=lambda stage, fraction: None, timer=timer,
            )  # fmt: skip
        finally:
            krylov._ritz_pairs = ordinary
        columns += band_columns
        step = 2 * block
        for start in range(0, Y.shape[1], step):
            with timer("refinement"):
                Y[:, start : start + step] = apply_op(Y[:, start : start + step])
        columns += Y.shape[1]
        factor.release()
        with timer("rayleigh_ritz"):
            lam = _rayleigh_ritz_in_place(K, inv_sqrt_m, Y)
        radius = np.abs(lam - sigma).max()
        if sigma - radius >= top * (1.0 - 1e-9):
            raise SliceGap(
                f"band at sigma={sigma:.6g} covers ({sigma - radius:.6g}, "
                f"{sigma + radius:.6g}), above the previous top {top:.6g}"
            )
        all_found = np.concatenate(lam_parts)
        below_sigma = int(np.count_nonzero(all_found < sigma)) + int(
            np.count_nonzero((lam < sigma) & (lam > top * (1.0 + 1e-8)))
        )
        checks.append(
            {
                "sigma": float(sigma),
                "inertia_below": negative,
                "found_below": below_sigma,
                "pairs": int(lam.shape[0]),
                "columns": int(band_columns) + int(lam.shape[0]),
                "stages": {s: t - before.get(s, 0.0) for s, t in timer.seconds.items()},
            }
        )
        keep_new = lam > top * (1.0 + 1e-8)  # the farthest pair found is complete too
        order = np.flatnonzero(keep_new)
        lam_parts.append(lam[order])
        X_parts.append(np.array(Y[:, order]))
        last_band = np.concatenate([last_band, lam[order]])[-max(order.shape[0], 8) :]
        found += order.shape[0]
        del Y, theta
    eigenvalues = np.concatenate(lam_parts)[:k]
    modes = np.hstack(X_parts)[:, :k]
    return eigenvalues, modes, timer.seconds, columns, checks
