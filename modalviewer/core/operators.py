"""The one list of operators modalviewer computes spectra of, and what each one is.

Every per-operator fact lives here: the label, the number of unknowns per vertex, the
function that assembles the matrix, the exactly known null space, the preview's reduced
space and from which size a preview pays, the signature and distance the spectrum
defines, and the cost.  Every other module (pipeline, preview, null space, viewer, CLI,
plots) asks this registry instead of keeping its own list or comparing operator names,
so a new operator is one more :class:`OperatorInfo` in :data:`OPERATOR_INFO`.

This module imports nothing of the package: the assembly functions are named by
``"module:function"`` inside :mod:`modalviewer.core` and imported when first used.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from .cost import (
    FILL_MARGIN,
    OUT_OF_CORE_TIME_FACTOR,
    FactorLaw,
    GrowthLaw,
    exact_peak_mb,
    factor_goes_out_of_core,
    float32_basis_saving_mb,
)

__all__ = [
    "OperatorInfo",
    "SpaceSettings",
    "OPERATOR_INFO",
    "OPERATOR_NAMES",
    "DISTANCE_KINDS",
    "NULL_SPACE_RULES",
    "distance_word",
    "operator_info",
    "operator_for_distance",
    "signature_kind",
]


@dataclass(frozen=True)
class SpaceSettings:
    """How the reduced space of a preview is built for one operator
    (:mod:`.preview`, :mod:`.reduced_space`)."""

    samples_min: int
    samples_per_mode: float
    degree: int
    """Polynomials times each partition-of-unity function: 1 = linear, 2 = quadratic."""
    radius_factor: float
    exact_sampling: bool
    """Farthest-point sampling over all vertices (an even covering, so the support
    radius is not set by one badly covered corner) instead of over random candidates."""
    smoothing: bool
    """The two-level step after the Galerkin projection (see
    :func:`.preview._two_level_step`)."""
    refine: bool = False
    """Subspace iteration with the fine operator where the estimate is above
    ``refine_above`` (see :func:`.preview.preview_spectrum`)."""
    refine_above: float | None = None
    """Largest estimated error left unrefined; None: :data:`.preview.REFINE_ABOVE`."""
    refine_steps: int | None = None
    """Subspace-iteration steps of a refinement; None: :data:`.preview.REFINE_STEPS`."""
    factor_step: bool = False
    """Correct the Galerkin pairs by Rayleigh-Ritz with residuals preconditioned by a
    single-precision factor of the fine operator (:func:`.preview._factor_steps`)
    instead of the two-level step, where that factor fits the memory limit."""

    def samples(self, k: int) -> int:
        return max(self.samples_min, int(self.samples_per_mode * k))


NULL_SPACE_RULES: dict[str, str] = {
    "constants": "the constant per component (scalar fields)",
    "rigid motions": "the six rigid motions per component (3-vector fields)",
    "normal translations": "f with f N a translation: the constant of flat components",
    "normal rigid motions": "f with f N a rigid motion: the affine functions of flat components",
}
"""How :func:`.nullspace.null_space` builds an operator's candidate null vectors; the
two ``normal`` rules need the vertex normals."""

RADIUS_FACTOR = 2.0
"""Support radius of the reduced space's basis functions in units of the sampling's
covering radius (the largest distance from a vertex to its nearest sample): the default
of :func:`.reduced_space.reduced_basis` and of the scalar operators' previews."""


@dataclass(frozen=True)
class OperatorInfo:
    """What the viewer and the library need to know about one operator.

    name : key used in files, the API and the cache.
    label : words for menus, legends and titles.
    short_label : a few words for narrow places (comparison titles, plot legends).
    unknowns_per_vertex : 3 for displacement fields, 1 for scalar fields.
    distance_kind : the multi-scale distance this operator's spectrum defines, or None.
    has_weights : whether the bending and membrane weights apply.
    assemble : ``"module:function"`` in :mod:`modalviewer.core` that assembles K:
        ``function(mesh)``, or ``function(mesh, bending, membrane)`` with weights
        (:meth:`stiffness`); with ``assembles_mass`` it returns (K, mass).
    null_space : the exactly known null vectors in words.
    null_space_rule : how they are built, a key of :data:`NULL_SPACE_RULES`.
    preview : the preview's reduced space (:class:`SpaceSettings`).
    exact_growth, preview_growth : measured time and memory of the exact solve and of
        the fast preview against mesh size (:class:`.cost.GrowthLaw`), which predict
        whether a preview pays.
    factor_memory : the exact solver's factor in core and out of core against mesh
        size (:class:`.cost.FactorLaw`), which predicts the memory of a solve whose
        factor goes out of core.
    signature_word : the signature (and distance) its spectrum defines, in words
        ("heat kernel"), or None.
    assembles_mass : whether :attr:`assemble` returns the (n,) masses with K (an
        operator with a mass of its own); otherwise the mass is the lumped vertex area.
    measured_as : the operator whose measured laws (:attr:`exact_growth`,
        :attr:`preview_growth`, :attr:`factor_memory`) this one borrows, or None: its own
        runs in ``benchmarks/results/growth.json``.
    nonnegative_weights : whether its weights stay non-negative on any mesh, so that the
        viewer suggests it where the cotan weights go negative.
    wave_distance_kind : the distance of the wave kernel signature of its spectrum
        offered by the viewer and the CLI (``"wks"`` for the Laplacian), or None; the
        library computes that signature for any spectrum
        (:func:`.signatures.signature`).
    preview_arrays_per_mode : float64 arrays of the unknowns' length a fast preview
        holds at its peak for each mode beyond the 100 its growth law was measured with
        (:meth:`predicted_peak_mb`).  The 300-mode runs on the 337k plate
        (``benchmarks/results/growth_k300.json``) needed 1.0 (Laplacian, E_D^N), 2.2 (3D
        shells) and 2.7 (normal shells) more per mode; tests/core/test_cost.py checks that
        these cover them.
    """

    name: str
    label: str
    short_label: str
    unknowns_per_vertex: int
    distance_kind: str | None
    has_weights: bool
    assemble: str
    null_space: str
    null_space_rule: str
    preview: SpaceSettings
    exact_growth: GrowthLaw
    preview_growth: GrowthLaw
    factor_memory: FactorLaw | None = None
    signature_word: str | None = None
    preview_arrays_per_mode: float = 3.0
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

    def growth(self, accuracy: str) -> GrowthLaw:
        """:attr:`exact_growth` ("exact") or :attr:`preview_growth` ("fast preview")."""
        return {"exact": self.exact_growth, "fast preview": self.preview_growth}[accuracy]

    def predicted_seconds(
        self, accuracy: str, n_vertices: int, k: int, out_of_core: bool | None = None
    ) -> float:
        """Seconds a ``compute_spectrum(mesh, name, k, accuracy=accuracy)`` ("exact" or
        "fast preview") on a mesh of ``n_vertices`` is predicted to take on the
        reference machine (:meth:`growth`); an exact solve whose factor goes out of
        core (``out_of_core``; None: as :meth:`factor_out_of_core` predicts) takes
        :data:`.cost.OUT_OF_CORE_TIME_FACTOR` times as long."""
        seconds = self.growth(accuracy).seconds(n_vertices, k)
        if accuracy == "exact" and self._out_of_core(n_vertices, k, out_of_core):
            seconds *= OUT_OF_CORE_TIME_FACTOR
        return seconds

    def predicted_peak_mb(
        self,
        accuracy: str,
        n_vertices: int,
        k: int = 100,
        out_of_core: bool | None = None,
        basis_float32: bool | None = None,
    ) -> float:
        """Peak memory (MB) of that computation with ``k`` modes: the exact solve's law
        with the arrays that grow with k (:func:`.cost.exact_peak_mb`), less the factor's
        in-core size plus its out-of-core size where the factor goes out of core
        (``out_of_core``; None: as :meth:`factor_out_of_core` predicts), plus the factor's
        further fill on curved meshes (:data:`.cost.FILL_MARGIN` times the factor's law
        for the place it is kept), less what a
        single-precision Krylov basis saves where it is kept so
        (:func:`.cost.float32_basis_saving_mb`; ``basis_float32``; None: as the solver
        decides, where the peak so far is above this machine's
        :func:`.memory.memory_limit_mb`); the fast preview's (measured at 100 modes)
        plus :attr:`preview_arrays_per_mode` float64 (N,) arrays for each mode above 100
        (its modes, the correction's directions and their blocks) and the same further
        fill of the factor as the exact solve's."""
        law = self.growth(accuracy)
        if accuracy != "exact":
            extra = self.preview_arrays_per_mode * 8.0 * self.unknowns(n_vertices) * max(0, k - 100)
            return law.peak_mb(n_vertices) + extra / 2**20 + self._further_fill_mb(n_vertices)
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
        self, n_vertices: int, k: int = 100, limit_mb: float | None = None
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
        peak = exact_peak_mb(self.growth("exact"), n_vertices, self.unknowns(n_vertices), k)
        return peak + self._further_fill_mb(n_vertices)

    def _further_fill_mb(self, n_vertices: int) -> float:
        """What a factor in core fills in on a curved mesh beyond the plates' law
        (:data:`.cost.FILL_MARGIN`).  Added to the previews' predictions too: they factor
        the same operator, and a preview is compared with the exact solve like for
        like."""
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

    def stiffness(self, mesh, bending: float = 1.0, membrane: float = 1.0):
        """The operator's sparse matrix K on ``mesh`` (the function :attr:`assemble`)."""
        return self.matrices(mesh, bending, membrane)[0]

    def matrices(self, mesh, bending: float = 1.0, membrane: float = 1.0):
        """(K, mass (n,) per vertex) on ``mesh``: the function :attr:`assemble`, and the
        lumped vertex areas unless it returns a mass of its own (:attr:`assembles_mass`)."""
        module, function = self.assemble.split(":")
        assemble = getattr(importlib.import_module(f"modalviewer.core.{module}"), function)
        result = assemble(mesh, bending, membrane) if self.has_weights else assemble(mesh)
        if self.assembles_mass:
            return result
        from .laplacian import lumped_masses

        return result, lumped_masses(mesh)


# Preview spaces.  Without smoothing the space itself must be fine (10k spot, Galerkin
# alone: 200 / 300 samples, largest error 2.0 / 1.4 %); the support radius comes from the
# covering radius of random-candidate sampling, which the 130k plate's lowest 50
# eigenvalues need (0.24 % largest error against 1.1 % with an even sampling and 2
# spacings).  Curved meshes with thin parts and sharp edges need more samples: Laplacian,
# 100 modes, lowest 50 non-zero eigenvalues, largest error with 300 / 600 samples: hand
# Loop x2 (206k, thin fingers) 2.7 / 0.44 %, machined part split flat x3 (266k, sharp
# edges) 2.2 / 1.26 %, spot Loop x3 (187k) 0.97 / 0.27 %.  From 200 modes on the space has
# 3 samples per mode, as the plates' 300-mode previews measured in growth_k300.json.
# Where the estimate stays above 0.7 % (the target 1 % and the estimate's measured
# shortfall: it read 1.0 % where the part was 1.26 % off) one subspace-iteration step
# with the fine operator follows (the part: 0.002 %, about 6 s).  The plates' estimates
# are 0.2 to 0.5 %, so their previews and the fitted growth laws are unrefined.
_SCALAR_SPACE = SpaceSettings(
    600, 3.0, 1, RADIUS_FACTOR, False, False, refine=True, refine_above=0.007, refine_steps=1
)

# Bending energies need quadratic precision, and the Galerkin error of smooth spaces
# stays near 5 % median on the 130k plate for 60 to 300 samples (membrane locking on
# the bumps), which the two-level step (see preview._two_level_step) removes.  130k
# plate, 100 modes, lowest 50 non-zero eigenvalues, largest / median error: normal
# shells, 200 samples 0.48 % / 0.18 % (3.6 s; 100 samples 1.5 %, radius 1.5: 2.5 %);
# shells, 100 samples, radius factor 1.8: 0.66 % / 0.27 %.  A radius factor of 1.5 (a
# smaller overlap of the supports: the projection 1.8 -> 1.1 s, 5.5 s in all) leaves
# 1.7 % / 0.8 % there but doubles the error on curved meshes (spot Loop-subdivided
# twice: 108 % / 22 % against 45 % / 13 %; the 10k spot's lowest distance correlation
# 0.17 against 0.78).  Linear functions leave shells errors of 69 % (150 samples).
_NORMAL_SHELLS_SPACE = SpaceSettings(200, 2.0, 2, RADIUS_FACTOR, False, True)

# Curved meshes with thin parts lock the 3D shells' smooth space: the cow (46k, 100
# modes) 1057 % largest / 59 % median error, its tail's two modes missing.  One step
# preconditioned by a single-precision factor of the fine operator (factor_step, see
# preview._factor_steps) brings the lowest 50 of 100 modes within 1.5 % at about a
# quarter of the exact time on 187k to 266k-vertex curved meshes
# (benchmarks/results/curved.json); where that factor does not fit, the two-level step
# and two subspace-iteration steps (2.4 % / 0.1 % on the cow).  The normal shells'
# exact spectra take about 4 s at 50k, about what a preview and its refinement would
# (3.3 s against 3.7 s), so they are shown unrefined and the exact spectrum follows.
_SHELLS_SPACE = SpaceSettings(100, 1.0, 2, 1.8, True, True, refine=True, factor_step=True)

# exact_growth / preview_growth: the fits of benchmarks/results/growth.json (bumpy plates
# of 100k to 1M vertices, 100 modes) and growth_k300.json (the 337k plate, 300 modes: how
# the time grows with k), made by `python -m benchmarks.growth`; tests/core/test_cost.py
# checks that they are those fits.
_GROWTH: dict[tuple[str, str], GrowthLaw] = {
    ("laplacian", "exact"): GrowthLaw(8.401, 1.109, 410.0, 0.864, 1.23),
    ("laplacian", "fast preview"): GrowthLaw(2.888, 0.95, 324.7, 0.848, 0.496),
    ("modified_dirichlet", "exact"): GrowthLaw(8.935, 1.051, 411.7, 0.864, 1.162),
    ("modified_dirichlet", "fast preview"): GrowthLaw(2.967, 0.964, 320.8, 0.851, 0.534),
    ("shells", "exact"): GrowthLaw(50.105, 1.077, 1549.9, 1.026, 0.93),
    ("shells", "fast preview"): GrowthLaw(10.902, 1.139, 1298.5, 0.995, 0.627),
    ("shells_normal", "exact"): GrowthLaw(9.014, 1.535, 454.2, 0.893, 0.714),
    ("shells_normal", "fast preview"): GrowthLaw(6.455, 0.998, 419.0, 0.862, 0.647),
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
            preview=_SCALAR_SPACE,
            exact_growth=_GROWTH["laplacian", "exact"],
            preview_growth=_GROWTH["laplacian", "fast preview"],
            factor_memory=_FACTOR["laplacian"],
            signature_word="heat kernel",
            preview_arrays_per_mode=1.25,
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
            preview=_SCALAR_SPACE,
            exact_growth=_GROWTH["modified_dirichlet", "exact"],
            preview_growth=_GROWTH["modified_dirichlet", "fast preview"],
            factor_memory=_FACTOR["modified_dirichlet"],
            signature_word="feature",
            preview_arrays_per_mode=1.25,
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
            preview=_SHELLS_SPACE,
            exact_growth=_GROWTH["shells", "exact"],
            preview_growth=_GROWTH["shells", "fast preview"],
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
            preview=_SCALAR_SPACE,
            # the cotan Laplacian's laws: as many unknowns, a matrix of about the same
            # sparsity (the intrinsic flips replace edges, keeping their number)
            exact_growth=_GROWTH["laplacian", "exact"],
            preview_growth=_GROWTH["laplacian", "fast preview"],
            factor_memory=_FACTOR["laplacian"],
            preview_arrays_per_mode=1.25,
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
            preview=_NORMAL_SHELLS_SPACE,
            exact_growth=_GROWTH["shells_normal", "exact"],
            preview_growth=_GROWTH["shells_normal", "fast preview"],
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


def operator_info(name: str) -> OperatorInfo:
    """The registry entry of ``name``; a ValueError naming the known operators otherwise."""
    try:
        return OPERATOR_INFO[name]
    except KeyError:
        raise ValueError(
            f"unknown operator {name!r}; choose one of {', '.join(OPERATOR_NAMES)}"
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
