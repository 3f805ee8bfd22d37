"""Time and memory estimates of a spectrum computation, from its size alone."""

from __future__ import annotations

__all__ = ["estimate_cost", "SECONDS_PER_UNKNOWN_MODE"]

SECONDS_PER_UNKNOWN_MODE = 1.5e-6
"""Eigen-solve time per unknown and mode on the 2-core reference machine with the block
Krylov-Schur solver and PARDISO (``make bench`` on 2026-11-23, third run, shells, 300
modes: 35k unknowns 14.1 s, 141k 59.5 s, 391k 177.8 s)."""


def estimate_cost(n_unknowns: int, k: int, nnz: int) -> tuple[float, float]:
    """(seconds, bytes) a spectrum of ``k`` modes of an (N, N) operator with ``nnz`` entries
    is expected to take on the reference machine: the Krylov basis with the factor while
    iterating, then with the compact copy of the modes (the factor is freed by then)."""
    k_work = k + max(8, k // 10)
    basis = 8.0 * n_unknowns * (1.6 * k_work + 32)
    modes = 8.0 * n_unknowns * k
    factor = 8.0 * 12.0 * nnz
    return SECONDS_PER_UNKNOWN_MODE * n_unknowns * k, basis + max(factor, modes)
