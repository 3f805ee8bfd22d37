"""The one list of operators modalviewer computes spectra of, and what each one is.

Every per-operator fact lives in its :class:`OperatorInfo` in :data:`OPERATOR_INFO`, so
a new operator is one more entry and its assembly function (named ``"module:function"``
and imported when used).  Public functions accept a name or an :class:`OperatorInfo`
(:data:`OperatorLike`), resolve it once with :func:`operator_info` and pass it on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .factor import available_backends
from .memory import (
    FILL_MARGIN,
    FactorLaw,
    GrowthLaw,
    exact_peak_mb,
    float32_basis_saving_mb,
    memory_limit_mb,
)

DEFAULT_K = 100  # the number of modes computed where none is given (as in the paper's figures)


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

    ``name`` keys files, the API and the cache; ``assemble`` is the function that
    assembles K (or its ``"module:function"`` in :mod:`modalviewer.core`), called with
    the bending and membrane weights where ``has_weights``, returning the mass too where
    ``assembles_mass`` (else the lumped vertex areas); ``null_space_rule`` is a key of
    :data:`NULL_SPACE_RULES`; ``exact_growth`` and ``factor_memory`` are the measured
    laws the memory check predicts from (``measured_as``: the operator whose laws they
    are, where not its own); ``nonnegative_weights``: its weights stay non-negative on
    any mesh (the viewer suggests it where the cotan weights go negative).
    """

    name: str
    label: str
    short_label: str
    assemble: str | Callable
    null_space: str
    exact_growth: GrowthLaw
    null_space_rule: str = "constants"
    unknowns_per_vertex: int = 1
    has_weights: bool = False
    factor_memory: FactorLaw | None = None
    distance_kind: str | None = None
    signature_word: str | None = None
    wave_distance_kind: str | None = None
    assembles_mass: bool = False
    measured_as: str | None = None
    nonnegative_weights: bool = False

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
        (:func:`.memory.exact_peak_mb` with :data:`.memory.FILL_MARGIN` on the factor).
        ``out_of_core``: the factor kept in a file; ``basis_float32``: a single-precision
        Krylov basis (:func:`.memory.float32_basis_saving_mb`); None for either: as the
        solver decides against :func:`.memory.memory_limit_mb`."""
        peak = self._in_core_peak_mb(n_vertices, k)
        if out_of_core is None:
            out_of_core = self.factor_out_of_core(n_vertices, k)
        factor = self.factor_memory
        if out_of_core and factor is not None:
            peak += FILL_MARGIN * (
                factor.out_of_core_mb(n_vertices) - factor.in_core_mb(n_vertices)
            )
        if basis_float32 is None:
            limit_mb = memory_limit_mb()
            basis_float32 = limit_mb is not None and peak > limit_mb
        if basis_float32:
            peak -= float32_basis_saving_mb(self.unknowns(n_vertices), k)
        return peak

    def factor_out_of_core(
        self, n_vertices: int, k: int = DEFAULT_K, limit_mb: float | None = None
    ) -> bool:
        """Whether the exact solve of ``k`` modes on ``n_vertices`` is predicted to keep
        its factor in a file: the in-core peak above ``limit_mb`` (None: this machine's
        :func:`.memory.memory_limit_mb`), out of core needing less, and PARDISO (the only
        backend with that mode) there."""
        limit_mb = memory_limit_mb() if limit_mb is None else limit_mb
        peak, factor = self._in_core_peak_mb(n_vertices, k), self.factor_memory
        if factor is None or limit_mb is None or peak <= limit_mb:
            return False
        if factor.out_of_core_mb(n_vertices) >= factor.in_core_mb(n_vertices):
            return False
        return "pardiso" in available_backends()

    def _in_core_peak_mb(self, n_vertices: int, k: int) -> float:
        """The predicted peak with the factor in core: the law with the arrays that grow
        with k, and the factor at :data:`.memory.FILL_MARGIN` times its law (curved meshes
        fill in more than the plates the law comes from)."""
        peak = exact_peak_mb(self.exact_growth, n_vertices, self.unknowns(n_vertices), k)
        if self.factor_memory is not None:
            peak += (FILL_MARGIN - 1.0) * self.factor_memory.in_core_mb(n_vertices)
        return peak


# exact_growth, factor_memory: the fits of benchmarks/results/growth.json and
# factor_memory.json (python -m benchmarks.growth, benchmarks.factor_memory: bumpy plates
# of 100k to 1M vertices, 100 modes), checked by tests/core/test_cost.py.
_LAPLACIAN_GROWTH = GrowthLaw(410.0, 0.864)
_SCALAR_FACTOR = FactorLaw(60.0, 1.042, 106.8, 0.689)

OPERATOR_INFO: dict[str, OperatorInfo] = {
    info.name: info
    for info in (
        OperatorInfo(
            "laplacian",
            "Laplacian (cotan)",
            "Laplacian",
            assemble="laplacian:stiffness_matrix",
            null_space="constants",
            exact_growth=_LAPLACIAN_GROWTH,
            factor_memory=_SCALAR_FACTOR,
            distance_kind="hks",
            signature_word="heat kernel",
            wave_distance_kind="wks",
        ),
        OperatorInfo(
            "modified_dirichlet",
            "Modified Dirichlet energy E_D^N",
            "E_D^N",
            assemble="laplacian:modified_dirichlet_matrix",
            null_space="constants of flat components",
            null_space_rule="normal translations",
            exact_growth=GrowthLaw(411.7, 0.864),
            factor_memory=_SCALAR_FACTOR,
            distance_kind="feature",
            signature_word="feature",
        ),
        OperatorInfo(
            "shells",
            "Discrete Shells (3D vibrations)",
            "Shells 3D",
            assemble="shells:shells_hessian",
            null_space="rigid motions",
            null_space_rule="rigid motions",
            unknowns_per_vertex=3,
            has_weights=True,
            exact_growth=GrowthLaw(1549.9, 1.026),
            factor_memory=FactorLaw(855.7, 1.087, 519.8, 0.952),
            distance_kind="vibration",
            signature_word="vibration",
        ),
        OperatorInfo(
            "laplacian_robust",
            "Laplacian (robust, intrinsic Delaunay)",
            "Robust Laplacian",
            assemble="robust:robust_laplacian_matrices",
            assembles_mass=True,
            null_space="constants",
            # the cotan Laplacian's laws: as many unknowns, a matrix of about the same
            # sparsity (the intrinsic flips replace edges, keeping their number)
            exact_growth=_LAPLACIAN_GROWTH,
            factor_memory=_SCALAR_FACTOR,
            measured_as="laplacian",
            nonnegative_weights=True,
        ),
        OperatorInfo(
            "shells_normal",
            "Discrete Shells, normal variations",
            "Shells normal",
            assemble="shells:normal_shells_hessian",
            null_space="normal rigid motions of flat components",
            null_space_rule="normal rigid motions",
            has_weights=True,
            exact_growth=GrowthLaw(454.2, 0.893),
            factor_memory=FactorLaw(110.9, 1.082, 125.8, 0.752),
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
    """The registry entry of a name (an :class:`OperatorInfo` as it is); a ValueError
    naming the known operators otherwise."""
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
    """The signature kind distance ``kind`` is made of: "wks" or "heat"."""
    info = operator_info(operator_for_distance(kind))
    return "wks" if kind == info.wave_distance_kind else "heat"


def distance_word(kind: str) -> str:
    """Distance ``kind`` in lower-case words ("heat kernel" for ``"hks"``)."""
    if signature_kind(kind) == "wks":
        return "wave kernel"
    word = operator_info(operator_for_distance(kind)).signature_word
    return word if word is not None else kind
