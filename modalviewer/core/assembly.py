"""``operator_matrices``: the (K, mass) of an operator's eigenproblem on a mesh, K from
the registry's assembly function (:attr:`.operators.OperatorInfo.assemble`), the mass
the lumped vertex area (or the operator's own) repeated for each unknown of a vertex.
"""

from __future__ import annotations

import numpy as np

from .mesh import Mesh
from .operators import OperatorLike, operator_info


def operator_matrices(
    mesh: Mesh, operator: OperatorLike, bending: float = 1.0, membrane: float = 1.0
):
    """(K, mass_diag) of the eigenproblem ``K phi = lambda diag(mass) phi``."""
    info = operator_info(operator)  # a ValueError naming the known operators
    K, m = info.matrices(mesh, bending, membrane)
    if info.unknowns_per_vertex > 1:
        m = np.repeat(m, info.unknowns_per_vertex)
    return K, m
