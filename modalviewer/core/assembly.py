"""The (K, mass) of an operator's eigenproblem on a mesh, from the registry."""

from __future__ import annotations

import importlib

import numpy as np

from .laplacian import lumped_masses
from .mesh import Mesh
from .operators import OperatorLike, operator_info


def operator_matrices(
    mesh: Mesh, operator: OperatorLike, bending: float = 1.0, membrane: float = 1.0
):
    """(K, mass_diag) of the eigenproblem ``K phi = lambda diag(mass) phi``: the function
    :attr:`~.operators.OperatorInfo.assemble` (a ``"module:function"`` of this package
    imported when used), with the lumped vertex areas unless it returns a mass of its
    own (:attr:`~.operators.OperatorInfo.assembles_mass`)."""
    info = operator_info(operator)  # a ValueError naming the known operators
    assemble = info.assemble
    if isinstance(assemble, str):
        module, function = assemble.split(":")
        assemble = getattr(importlib.import_module(f"modalviewer.core.{module}"), function)
    result = assemble(mesh, bending, membrane) if info.has_weights else assemble(mesh)
    K, m = result if info.assembles_mass else (result, lumped_masses(mesh))
    if info.unknowns_per_vertex > 1:
        m = np.repeat(m, info.unknowns_per_vertex)
    return K, m
