"""Coarse-to-fine (paper Section 7, Fig. 9) and cost estimates for big problems."""

from __future__ import annotations

from scipy.spatial import cKDTree

from .laplacian import lumped_masses
from .mesh import Mesh
from .spectrum import Spectrum

__all__ = ["transfer_spectrum", "estimate_cost"]

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


def transfer_spectrum(coarse_spec: Spectrum, coarse: Mesh, fine: Mesh) -> Spectrum:
    """Carry a coarse mesh's spectrum to the fine mesh by nearest-vertex lookup.

    Eigenvalues are kept; each fine vertex takes the modes of the nearest coarse vertex.
    The transferred modes are not Mass-orthonormal on the fine mesh; signatures and
    distances computed from them approximate the fine ones (correlation 0.94 for the
    vibration distance on the demo hand decimated to a fifth).
    """
    _, nearest = cKDTree(coarse.vertices).query(fine.vertices)
    params = dict(coarse_spec.parameters)
    params.update(transferred_from=coarse.hash, coarse_vertices=coarse.n_vertices)
    return Spectrum(
        eigenvalues=coarse_spec.eigenvalues.copy(),
        modes=coarse_spec.modes[nearest].copy(),
        operator=coarse_spec.operator,
        mass=lumped_masses(fine),
        residuals=coarse_spec.residuals.copy(),
        mesh_hash=fine.hash,
        parameters=params,
    )
