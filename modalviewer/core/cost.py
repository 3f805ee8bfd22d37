"""Time and memory estimates of a spectrum computation, from its size alone."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "estimate_cost",
    "SECONDS_PER_UNKNOWN_MODE",
    "GrowthLaw",
]

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


@dataclass(frozen=True)
class GrowthLaw:
    """Seconds and peak memory of one computation as powers of the mesh size and of the
    number of modes, measured on the reference machine (``benchmarks/growth.py``: bumpy
    plates of 100k to 1M vertices with 100 modes, each run in its own process, and the
    337k plate with 300 modes for ``mode_exponent``; ``benchmarks/results/growth.json``
    and ``growth_k300.json`` hold the runs)."""

    seconds_at_100k: float
    time_exponent: float
    peak_mb_at_100k: float
    memory_exponent: float
    mode_exponent: float = 1.0

    def seconds(self, n_vertices: int, k: int) -> float:
        """Predicted seconds for ``k`` modes: the fit at 100 modes times
        ``(k / 100) ** mode_exponent``."""
        size = max(int(n_vertices), 1) / 1e5
        return self.seconds_at_100k * size**self.time_exponent * (k / 100) ** self.mode_exponent

    def peak_mb(self, n_vertices: int) -> float:
        """Predicted peak resident memory (MB) of the computing process, at 100 modes."""
        size = max(int(n_vertices), 1) / 1e5
        return self.peak_mb_at_100k * size**self.memory_exponent
