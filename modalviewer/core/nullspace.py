"""The exactly known null spaces of the operators, per connected component.

Each energy is a sum over the connected components, so its null space is the direct sum
of theirs.  Known exactly, per component (the registry's
:attr:`.operators.OperatorInfo.null_space_rule`): the constant (Laplacian), the six
rigid motions (shells), and on a *flat* component only the constant (E_D^N: ``f_i N_i``
constant) or the three affine functions of the plane (normal shells: ``f_i N_i`` a rigid
motion).  Other null vectors (shells pieces meeting at one vertex) are found by the
eigensolver like any other mode.  Every candidate is checked on the assembled matrix
against :data:`NULL_RTOL` (a nearly flat component's constant fails for E_D^N).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .laplacian import vertex_normals
from .mesh import Mesh
from .operators import OperatorInfo, OperatorLike, operator_info
from .products import column_norms

NULL_RTOL = 1e-10
"""A candidate null vector z is accepted if ``|K z| <= NULL_RTOL * | |K| |z| |``: exact
null vectors reach 1e-16 to 1e-14 (rounding in the assembly and the product)."""


@dataclass(frozen=True)
class NullSpace:
    """Exact null vectors of one operator on one mesh: ``vectors`` (N, d) sparse CSC,
    ``vectors.T @ diag(mass) @ vectors = I`` and ``K @ vectors = 0`` to rounding, each
    column on one component, ordered by component; ``per_component`` counts them."""

    vectors: sp.csc_matrix
    operator: OperatorInfo
    n_components: int
    per_component: np.ndarray

    @property
    def dimension(self) -> int:
        return int(self.vectors.shape[1])

    def summary(self) -> str:
        """One sentence on the zero modes a spectrum of this operator starts with."""
        d, c = self.dimension, self.n_components
        comps = f"{c} connected component{'s' if c != 1 else ''}"
        kind = self.operator.null_space
        if d == 0:
            return f"{comps}; no exactly known zero modes ({kind}: none)."
        with_null = self.per_component[self.per_component > 0]
        counts = np.unique(with_null)
        if len(with_null) == c and len(counts) == 1:
            where = f"{counts[0]} per component"
        else:
            where = f"on {len(with_null)} of the {c} components"
        first = f"the first {d} modes are exact zero modes"
        if d == 1:
            first = "the first mode is an exact zero mode"
        return f"{comps}: {first} ({kind}, {where}), computed directly, not by iteration."


def _rigid_fields(x: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(p, 3, 6) velocities of 3 translations and 3 rotations about the centre of mass."""
    c = (m[:, None] * x).sum(axis=0) / m.sum()
    r = x - c
    fields = np.zeros((len(x), 3, 6))
    fields[:, [0, 1, 2], [0, 1, 2]] = 1.0
    for a, axis in enumerate(np.eye(3)):
        fields[:, :, 3 + a] = np.cross(axis, r)
    return fields


def _mass_orthonormal(B: np.ndarray, w: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """Columns spanning B's range, orthonormal in the weights w (eigenvectors of the
    Gram matrix, so principal directions come out; rank-deficient parts dropped)."""
    if B.shape[1] == 0:
        return B
    G = B.T @ (w[:, None] * B)
    ev, V = np.linalg.eigh(0.5 * (G + G.T))
    keep = ev > rtol * max(float(ev.max()), np.finfo(float).tiny)
    return B @ (V[:, keep] / np.sqrt(ev[keep]))


def _candidates(mesh: Mesh, info: OperatorInfo, mass: np.ndarray, normals):
    """Per component: (rows of the unknowns, Mass-orthonormal dense candidate columns)."""
    x = mesh.vertices
    rule, per_vertex = info.null_space_rule, info.unknowns_per_vertex
    labels = mesh.component_labels
    order = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[order], np.arange(labels.max() + 2))
    for verts in (order[bounds[c] : bounds[c + 1]] for c in range(len(bounds) - 1)):
        m = mass[per_vertex * verts]
        if rule == "constants":
            yield verts, _mass_orthonormal(np.ones((len(verts), 1)), m)
        elif rule == "rigid motions":
            fields = _rigid_fields(x[verts], m)  # (p, 3, 6), rows 3i+c
            rows = (3 * verts[:, None] + np.arange(3)).ravel()
            yield rows, _mass_orthonormal(fields.reshape(-1, 6), np.repeat(m, 3))
        else:  # "normal translations", "normal rigid motions"
            fields = _rigid_fields(x[verts], m)
            if rule == "normal translations":
                fields = fields[:, :, :3]  # f N constant: translations only
            N = normals[verts]
            along = np.einsum("pc,pcj->pj", N, fields)  # normal component f = N . r
            tangential = fields - N[:, :, None] * along[:, None, :]
            # rigid motions that are normal everywhere: the null space of the tangential
            # parts (relative to the whole motion; rotations and translations differ in size)
            T = (np.sqrt(m)[:, None, None] * tangential).reshape(-1, fields.shape[2])
            whole = (np.sqrt(m)[:, None, None] * fields).reshape(-1, fields.shape[2])
            _, s, Vt = np.linalg.svd(T, full_matrices=False)
            size = np.linalg.norm(whole @ Vt.T, axis=0)
            ok = s <= 1e-8 * size
            yield verts, _mass_orthonormal(along @ Vt[ok].T, m)


def null_space(mesh: Mesh, operator: OperatorLike, K: sp.spmatrix, mass: np.ndarray) -> NullSpace:
    """The exactly known null vectors of ``operator`` on ``mesh``, checked against its
    matrix ``K`` (mass: its diagonal mass)."""
    info = operator_info(operator)  # a ValueError naming the known operators
    mass = np.asarray(mass, dtype=np.float64)
    # E_D^N and the normal shells are built with the area-weighted vertex normals
    normals = vertex_normals(mesh) if info.null_space_rule.startswith("normal") else None
    rows, cols, vals = [], [], []
    component = []
    for c, (comp_rows, Z) in enumerate(_candidates(mesh, info, mass, normals)):
        r, j = np.nonzero(Z)
        rows.append(comp_rows[r])
        cols.append(j + len(component))
        vals.append(Z[r, j])
        component.extend([c] * Z.shape[1])
    n_components = c + 1
    d = len(component)
    Z = sp.csc_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(K.shape[0], d),
    )
    if d:
        # one sparse product for every candidate; a subset of orthonormal columns that
        # live on disjoint components stays orthonormal
        K = sp.csr_matrix(K)
        KZ = (K @ Z).tocsc()
        bound = (abs(K) @ abs(Z)).tocsc()
        exact = column_norms(KZ) <= NULL_RTOL * column_norms(bound)
        Z = Z[:, np.flatnonzero(exact)]
        component = np.asarray(component)[exact]
    per_component = np.bincount(np.asarray(component, dtype=np.int64), minlength=n_components)
    return NullSpace(sp.csc_matrix(Z), info, n_components, per_component)
