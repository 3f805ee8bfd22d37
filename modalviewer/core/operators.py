"""The one list of operators modalviewer computes spectra of, and what each one is.

Every per-operator fact lives in its :class:`OperatorInfo` in :data:`OPERATOR_INFO`;
other modules ask the registry instead of comparing names, so a new operator is one
more entry and its assembly function.  Public functions accept a name or an
:class:`OperatorInfo` (:data:`OperatorLike`), resolve it once with
:func:`operator_info` and pass the object on.  This module imports nothing of the
package: assembly functions are named ``"module:function"`` and imported when used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass

from .cost import (
    FILL_MARGIN,
    FactorLaw,
    GrowthLaw,
    exact_peak_mb,
    factor_goes_out_of_core,
    float32_basis_saving_mb,
)

__all__ = [
    "DEFAULT_K",
    "default_k",
    "OperatorInfo",
    "OperatorLike",
    "OPERATOR_INFO",
    "OPERATOR_NAMES",
    "DISTANCE_KINDS",
    "NULL_SPACE_RULES",
    "distance_word",
    "operator_info",
    "operator_for_distance",
    "signature_kind",
]

DEFAULT_K = 100
"""The number of modes computed where none is given (the paper's figures use 100)."""


def default_k(n_vertices: int) -> int:
    """A mode count suited to a mesh: :data:`DEFAULT_K`, fewer for tiny meshes."""
    return int(max(2, min(DEFAULT_K, n_vertices // 4)))


NULL_SPACE_RULES: dict[str, str] = {
    "constants": "the constant per component (scalar fields)",
    "rigid motions": "the six rigid motions per component (3-vector fields)",
    "normal translations": "f with f N a translation: the constant of flat components",
    "normal rigid motions": "f with f N a rigid motion: the affine functions of flat components",
}
"""How :func:`.nullspace.null_space` builds an operator's candidate null vectors; the
two ``normal`` rules need the vertex normals."""


@dataclass(frozen=True)
class OperatorInfo:
    """What the viewer and the library need to know about one operator.

    name : key used in files, the API and the cache.
    label : words for menus, legends and titles.
    short_label : a few words for narrow places (comparison titles, plot legends).
    unknowns_per_vertex : 3 for displacement fields, 1 for scalar fields.
    distance_kind : the multi-scale distance this operator's spectrum defines, or None.
    has_weights : whether the bending and membrane weights apply.
    assemble : the function that assembles K, or its ``"module:function"`` in
        :mod:`modalviewer.core`, called as ``function(mesh)`` or, with weights,
        ``function(mesh, bending, membrane)``.
    null_space : the exactly known null vectors in words.
    null_space_rule : how they are built, a key of :data:`NULL_SPACE_RULES`.
    exact_growth : measured peak memory of the exact solve against mesh size
        (:class:`.cost.GrowthLaw`), which the memory check predicts from.
    factor_memory : the factor's size in core and out of core against mesh size
        (:class:`.cost.FactorLaw`).
    signature_word : the signature (and distance) its spectrum defines, in words
        ("heat kernel"), or None.
    assembles_mass : whether :attr:`assemble` returns (K, mass (n,)); otherwise the mass
        is the lumped vertex area.
    measured_as : the operator whose measured laws this one borrows, or None (its own
        runs are in ``benchmarks/results/growth.json``).
    nonnegative_weights : whether its weights stay non-negative on any mesh (the viewer
        suggests it where the cotan weights go negative).
    wave_distance_kind : the wave kernel distance the viewer and the CLI offer for its
        spectrum (``"wks"`` for the Laplacian), or None.
    """

    name: str
    label: str
    short_label: str
    unknowns_per_vertex: int
    distance_kind: str | None
    has_weights: bool
    assemble: str | Callable
    null_space: str
    null_space_rule: str
    exact_growth: GrowthLaw
    factor_memory: FactorLaw | None = None
    signature_word: str | None = None
    wave_distance_kind: str | None = None
    assembles_mass: bool = False
    measured_as: str | None = None
    nonnegative_weights: bool = False

    @property
    def vector(self) -> bool:
        """True for 3-vector (displacement) fields, False for scalar fields."""
        return self.unknowns_per_vertex == 3

    def unknowns(self, n_vertices: int) -> int:
        return self.unknowns_per_vertex * int(n_vertices)

    def predicted_peak_mb(
        self,
        n_vertices: int,
        k: int = DEFAULT_K,
        out_of_core: bool | None = None,
        basis_float32: bool | None = None,
    ) -> float:
        """Predicted peak memory (MB) of an exact solve of ``k`` modes on ``n_vertices``
        (:func:`.cost.exact_peak_mb` with :data:`.cost.FILL_MARGIN` on the factor).
        ``out_of_core``: the factor kept in a file; ``basis_float32``: a single-precision
        Krylov basis (:func:`.cost.float32_basis_saving_mb`); None for either: as the
        solver decides against :func:`.memory.memory_limit_mb`."""
        peak = self._in_core_peak_mb(n_vertices, k)
        if self._out_of_core(n_vertices, k, out_of_core):
            factor = self.factor_memory
            peak += FILL_MARGIN * (
                factor.out_of_core_mb(n_vertices) - factor.in_core_mb(n_vertices)
            )
        if basis_float32 is None:
            from .memory import memory_limit_mb

            limit_mb = memory_limit_mb()
            basis_float32 = limit_mb is not None and peak > limit_mb
        if basis_float32:
            peak -= float32_basis_saving_mb(self.unknowns(n_vertices), k)
        return peak

    def factor_out_of_core(
        self, n_vertices: int, k: int = DEFAULT_K, limit_mb: float | None = None
    ) -> bool:
        """Whether the exact solve of ``k`` modes on ``n_vertices`` is predicted to keep
        its factor in a file: its in-core peak above ``limit_mb`` (None: this machine's
        :func:`.memory.memory_limit_mb`), as the solver decides
        (:func:`.cost.factor_goes_out_of_core`)."""
        if limit_mb is None:
            from .memory import memory_limit_mb

            limit_mb = memory_limit_mb()
        peak = self._in_core_peak_mb(n_vertices, k)
        return factor_goes_out_of_core(peak, self.factor_memory, n_vertices, limit_mb)

    def _in_core_peak_mb(self, n_vertices: int, k: int) -> float:
        """The exact solve's predicted peak with its factor in core: the law with the
        arrays that grow with k (:func:`.cost.exact_peak_mb`) and the factor at
        :data:`.cost.FILL_MARGIN` times its law."""
        peak = exact_peak_mb(self.exact_growth, n_vertices, self.unknowns(n_vertices), k)
        return peak + self._further_fill_mb(n_vertices)

    def _further_fill_mb(self, n_vertices: int) -> float:
        """What a factor in core fills in on a curved mesh beyond the plates' law
        (:data:`.cost.FILL_MARGIN`)."""
        if self.factor_memory is None:
            return 0.0
        return (FILL_MARGIN - 1.0) * self.factor_memory.in_core_mb(n_vertices)

    def _out_of_core(self, n_vertices: int, k: int, out_of_core: bool | None) -> bool:
        if out_of_core is None:
            return self.factor_out_of_core(n_vertices, k)
        return bool(out_of_core) and self.factor_memory is not None

    @property
    def null_space_needs_normals(self) -> bool:
        return self.null_space_rule.startswith("normal")

    def matrices(self, mesh, bending: float = 1.0, membrane: float = 1.0):
        """(K, mass (n,) per vertex) on ``mesh``: the function :attr:`assemble`, and the
        lumped vertex areas unless it returns a mass of its own (:attr:`assembles_mass`)."""
        assemble = self.assemble
        if isinstance(assemble, str):
            module, function = assemble.split(":")
            assemble = getattr(importlib.import_module(f"modalviewer.core.{module}"), function)
        result = assemble(mesh, bending, membrane) if self.has_weights else assemble(mesh)
        if self.assembles_mass:
            return result
        from .laplacian import lumped_masses

        return result, lumped_masses(mesh)


# exact_growth: the memory fits of benchmarks/results/growth.json (bumpy plates of 100k to
# 1M vertices, 100 modes), made by `python -m benchmarks.growth`; tests/core/test_cost.py
# checks that they are those fits.
_GROWTH: dict[str, GrowthLaw] = {
    "laplacian": GrowthLaw(410.0, 0.864),
    "modified_dirichlet": GrowthLaw(411.7, 0.864),
    "shells": GrowthLaw(1549.9, 1.026),
    "shells_normal": GrowthLaw(454.2, 0.893),
}

# factor_memory: the fits of benchmarks/results/factor_memory.json (PARDISO's analysis of
# the bumpy plates of 100k to 1M vertices), made by `python -m benchmarks.factor_memory`;
# tests/core/test_cost.py checks that they are those fits.  Curved meshes fill in 1.1 to
# 1.2 times more (spot Loop x3, hand Loop x2: the same file's curved rows).
_FACTOR: dict[str, FactorLaw] = {
    "laplacian": FactorLaw(60.0, 1.042, 106.8, 0.689),
    "modified_dirichlet": FactorLaw(60.0, 1.042, 106.8, 0.689),
    "shells": FactorLaw(855.7, 1.087, 519.8, 0.952),
    "shells_normal": FactorLaw(110.9, 1.082, 125.8, 0.752),
}

OPERATOR_INFO: dict[str, OperatorInfo] = {
    info.name: info
    for info in (
        OperatorInfo(
            "laplacian",
            "Laplacian (cotan)",
            "Laplacian",
            unknowns_per_vertex=1,
            distance_kind="hks",
            has_weights=False,
            assemble="laplacian:stiffness_matrix",
            null_space="constants",
            null_space_rule="constants",
            exact_growth=_GROWTH["laplacian"],
            factor_memory=_FACTOR["laplacian"],
            signature_word="heat kernel",
            wave_distance_kind="wks",
        ),
        OperatorInfo(
            "modified_dirichlet",
            "Modified Dirichlet energy E_D^N",
            "E_D^N",
            unknowns_per_vertex=1,
            distance_kind="feature",
            has_weights=False,
            assemble="dirichlet:modified_dirichlet_matrix",
            null_space="constants of flat components",
            null_space_rule="normal translations",
            exact_growth=_GROWTH["modified_dirichlet"],
            factor_memory=_FACTOR["modified_dirichlet"],
            signature_word="feature",
        ),
        OperatorInfo(
            "shells",
            "Discrete Shells (3D vibrations)",
            "Shells 3D",
            unknowns_per_vertex=3,
            distance_kind="vibration",
            has_weights=True,
            assemble="shells:shells_hessian",
            null_space="rigid motions",
            null_space_rule="rigid motions",
            exact_growth=_GROWTH["shells"],
            factor_memory=_FACTOR["shells"],
            signature_word="vibration",
        ),
        OperatorInfo(
            "laplacian_robust",
            "Laplacian (robust, intrinsic Delaunay)",
            "Robust Laplacian",
            unknowns_per_vertex=1,
            distance_kind=None,
            has_weights=False,
            assemble="robust:robust_laplacian_matrices",
            null_space="constants",
            null_space_rule="constants",
            # the cotan Laplacian's laws: as many unknowns, a matrix of about the same
            # sparsity (the intrinsic flips replace edges, keeping their number)
            exact_growth=_GROWTH["laplacian"],
            factor_memory=_FACTOR["laplacian"],
            assembles_mass=True,
            measured_as="laplacian",
            nonnegative_weights=True,
        ),
        OperatorInfo(
            "shells_normal",
            "Discrete Shells, normal variations",
            "Shells normal",
            unknowns_per_vertex=1,
            distance_kind=None,
            has_weights=True,
            assemble="shells:normal_shells_hessian",
            null_space="normal rigid motions of flat components",
            null_space_rule="normal rigid motions",
            exact_growth=_GROWTH["shells_normal"],
            factor_memory=_FACTOR["shells_normal"],
        ),
    )
}
OPERATOR_NAMES: tuple[str, ...] = tuple(OPERATOR_INFO)

DISTANCE_KINDS: dict[str, str] = {
    "vibration": "Vibration distance",
    "feature": "Feature distance",
    "hks": "Heat kernel distance",
    "wks": "Wave kernel distance",
}
"""Distance kinds (paper Section 6, and the wave kernel's) and their names in words."""


OperatorLike = str | OperatorInfo
"""An operator as the public functions accept it: its name or its :class:`OperatorInfo`."""


def operator_info(operator: OperatorLike) -> OperatorInfo:
    """The operator object of ``operator``: the registry entry of a name, an
    :class:`OperatorInfo` as it is; a ValueError naming the known operators otherwise."""
    if isinstance(operator, OperatorInfo):
        return operator
    try:
        return OPERATOR_INFO[operator]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown operator {operator!r}; choose one of {', '.join(OPERATOR_INFO)}"
        ) from None


def operator_for_distance(kind: str) -> str:
    """The operator whose spectrum defines distance ``kind`` (vibration -> shells, ...)."""
    for info in OPERATOR_INFO.values():
        if kind in (info.distance_kind, info.wave_distance_kind):
            return info.name
    raise ValueError(f"unknown distance kind {kind!r}; choose one of {', '.join(DISTANCE_KINDS)}")


def signature_kind(kind: str) -> str:
    """The signature (:data:`.signatures.SIGNATURE_KINDS`) distance ``kind`` is made of:
    "wks" for a wave kernel distance, "heat" for the others."""
    info = operator_info(operator_for_distance(kind))
    return "wks" if kind == info.wave_distance_kind else "heat"


def distance_word(kind: str) -> str:
    """Distance ``kind`` in lower-case words ("heat kernel" for ``"hks"``, "wave
    kernel" for ``"wks"``)."""
    if signature_kind(kind) == "wks":
        return "wave kernel"
    word = operator_info(operator_for_distance(kind)).signature_word
    return word if word is not None else kind
