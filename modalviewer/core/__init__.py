"""Numerical core of modalviewer: numpy and scipy only (no Qt, no VTK)."""

from . import components, cross
from .cache import SpectrumCache
from .cleaning import repair_mesh
from .components import *  # noqa: F403
from .cross import *  # noqa: F403
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

__all__ = [
    *components.__all__,
    *cross.__all__,
    "Cancelled",
    "EigenError",
    "Mesh",
    "MeshError",
    "MeshReport",
    "OPERATORS",
    "SignatureTable",
    "Spectrum",
    "SpectrumFileError",
    "SpectrumCache",
    "compute_spectrum",
    "ZeroModesWarning",
    "default_energies",
    "FunctionalMap",
    "functional_map",
    "correspondence_errors",
    "negative_cotan_weights",
    "robust_laplacian_matrices",
    "default_times",
    "load_spectrum",
    "local_signature",
    "mass_matrix",
    "modified_dirichlet_matrix",
    "multiscale_distance",
    "normal_shells_hessian",
    "remove_unused",
    "repair_mesh",
    "save_spectrum",
    "shells_hessian",
    "signature",
    "stiffness_matrix",
    "k_for_truncation",
    "truncation_error",
    "vertex_normals",
]
