"""Numerical core of modalviewer: numpy and scipy only (no Qt, no VTK)."""
# ruff: noqa: F401 (the imports are the public API: __all__ is made of them below)

from types import ModuleType as _ModuleType

from .cache import SpectrumCache
from .cleaning import repair_mesh
from .components import (
    ComponentSpectrum,
    compute_spectrum_per_component,
    largest_component,
    split_components,
)
from .cross import (
    CrossTables,
    Matches,
    ScaleWarning,
    best_match,
    common_times,
    cross_distance,
    distance_ranks,
    mutual_best_matches,
    rescale_to_area,
)
from .eigen import Cancelled, EigenError
from .fmaps import FunctionalMap, correspondence_errors, functional_map
from .laplacian import mass_matrix, modified_dirichlet_matrix, stiffness_matrix, vertex_normals
from .local_signature import local_signature
from .mesh import Mesh, MeshError, MeshReport, remove_unused
from .pipeline import ZeroModesWarning, compute_spectrum
from .robust import negative_cotan_weights, robust_laplacian_matrices
from .shells import normal_shells_hessian, shells_hessian
from .signatures import (
    SignatureTable,
    default_energies,
    default_times,
    multiscale_distance,
    signature,
)
from .spectrum import OPERATORS, Spectrum, SpectrumFileError, load_spectrum, save_spectrum
from .truncation import k_for_truncation, truncation_error

# every public name imported above (the submodules themselves are not exported)
__all__ = [
    name
    for name, value in globals().items()
    if not name.startswith("_") and not isinstance(value, _ModuleType)
]
