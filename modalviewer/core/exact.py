"""The exact lowest eigenpairs of an operator on a mesh: the operator's matrices, its
exactly known null space, the shift-invert solve, and which pairs are zero modes.

:func:`.pipeline.compute_spectrum` checks their residuals and wraps them in a
:class:`.spectrum.Spectrum`."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from .assembly import operator_matrices
from .eigen import CancelFn, EigenResult, ProgressFn, solve_lowest, typical_eigenvalue, zero_modes
from .mesh import Mesh
from .nullspace import NullSpace, null_space
from .operators import OperatorInfo


class ModeSink(Protocol):
    """Receives the pairs of :func:`exact_pairs` as they converge."""

    def start(self, K, mass: np.ndarray, nulls: NullSpace, scale: float, k: int) -> None:
        """The problem: matrices, null space, typical eigenvalue, pairs to come."""

    def __call__(self, eigenvalues: np.ndarray, vectors: np.ndarray) -> None:
        """The next converged pairs, in order (see :func:`.eigen.solve_lowest`)."""


@dataclass(frozen=True)
class ExactPairs:
    """What :func:`exact_pairs` computed for ``K phi = lambda diag(mass) phi``."""

    K: sp.csr_matrix
    mass: np.ndarray
    nulls: NullSpace  # the operator's exact null vectors on the mesh (first in result)
    result: EigenResult  # the k lowest pairs (k capped at the number of unknowns)
    zero_mode_scale: float  # the typical eigenvalue zero modes are measured against
    nonzero: np.ndarray  # (k,) bool, the pairs that are not zero modes
    seconds_assembly: float


def exact_pairs(
    mesh: Mesh,
    operator: OperatorInfo,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    on_modes: ModeSink | None = None,
) -> ExactPairs:
    """The ``min(k, unknowns)`` lowest eigenpairs of ``operator`` on ``mesh``, the exact
    null vectors first.  ``on_modes`` is told the problem (:meth:`ModeSink.start`), then
    given the pairs as they converge.  Raises what the assembly, the null space and
    :func:`.eigen.solve_lowest` raise (:class:`.mesh.MeshError`,
    :class:`.eigen.EigenError`, :class:`.eigen.Cancelled`)."""
    started = time.perf_counter()
    K, mass = operator_matrices(mesh, operator, bending, membrane)
    seconds_assembly = time.perf_counter() - started
    k = min(int(k), K.shape[0])
    nulls = null_space(mesh, operator, K, mass)
    scale = typical_eigenvalue(K, mass)
    if on_modes is not None:
        on_modes.start(K, mass, nulls, scale, k)
    result = solve_lowest(
        K, mass, k, progress=progress, cancel=cancel, null_space=nulls.vectors, on_modes=on_modes
    )
    nonzero = ~zero_modes(result.eigenvalues, scale, result.null_dim)
    return ExactPairs(K, mass, nulls, result, scale, nonzero, seconds_assembly)
