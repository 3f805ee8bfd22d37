"""The :class:`Spectrum` result and its ``.npz`` storage (written atomically)."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .eigen import zero_modes
from .files import atomic_write
from .mesh import Mesh, _unused_words
from .operators import OPERATOR_INFO, OPERATOR_NAMES, OperatorInfo, operator_info

OPERATORS = OPERATOR_NAMES
FORMAT_VERSION = 1
SPECTRUM_ARRAYS = ("eigenvalues", "modes", "mass", "residuals")  # a spectrum file's arrays


class SpectrumFileError(ValueError):
    """A spectrum file is unreadable, foreign, or does not belong to the given mesh."""


@dataclass
class Spectrum:
    """Lowest eigenpairs of one operator on one mesh: ``eigenvalues`` (k,) ascending;
    ``modes`` (n, k), or (n, 3, k) for ``"shells"``, a row per vertex in the input
    numbering (NaN where no face uses it), M-orthonormal over the used rows (``M`` the
    lumped ``mass``), so values scale with 1 / sqrt(area); ``residuals`` (k,) relative,
    |K u - lambda M u| / |lambda M u|; ``from_cache``: read from the cache (not saved).
    """

    eigenvalues: np.ndarray
    modes: np.ndarray
    operator: str
    mass: np.ndarray
    residuals: np.ndarray
    mesh_hash: str = ""
    parameters: dict = field(default_factory=dict)
    from_cache: bool = field(default=False, compare=False)

    def __repr__(self) -> str:
        lam = self.eigenvalues
        span = f"{lam.min():.3g} .. {lam.max():.3g}" if lam.size else "none"
        return (
            f"Spectrum(operator={self.operator!r}, k={self.k}, n_vertices={self.n_vertices}, "
            f"modes={tuple(self.modes.shape)}, eigenvalues={span})"
        )

    @property
    def operator_info(self) -> OperatorInfo:
        return operator_info(self.operator)

    @property
    def k(self) -> int:
        return int(self.eigenvalues.shape[0])

    @property
    def n_vertices(self) -> int:
        return int(self.modes.shape[0])

    @property
    def is_vector(self) -> bool:
        return self.modes.ndim == 3

    @property
    def modes_requested(self) -> int:
        """How many modes the computation gives: more than :attr:`k` while they arrive."""
        return int(self.parameters.get("modes_requested", self.k))

    @property
    def is_complete(self) -> bool:
        """False for the first modes of a computation still running."""
        return self.k >= self.modes_requested

    @property
    def null_space_dimension(self) -> int:
        """How many of the first modes are deflated exact null vectors (:mod:`.nullspace`)."""
        return int(self.parameters.get("null_space_dimension", 0))

    def zero_mode_mask(self) -> np.ndarray:
        """(k,) True for the zero modes (the rule of :func:`.eigen.zero_modes`)."""
        scale = float(self.parameters.get("zero_mode_scale", 0.0))
        return zero_modes(self.eigenvalues, scale, self.null_space_dimension)

    def mode(self, j: int) -> np.ndarray:
        """Mode j: (n,) for scalar operators, (n, 3) for ``"shells"``."""
        return self.modes[..., j]

    def euclidean_modes(self) -> np.ndarray:
        """The modes scaled to Euclidean length 1 (each column of ``modes.reshape(-1, k)``
        has norm 1), same shape as ``modes``; a new array.  They are orthogonal in the
        mass inner product, not in the Euclidean one."""
        flat = self.modes.reshape(-1, self.k)
        faced = np.repeat(self.mass > 0, flat.shape[0] // max(self.mass.shape[0], 1))
        norms = np.linalg.norm(flat[faced], axis=0)
        return (flat / np.where(norms > 0, norms, 1.0)).reshape(self.modes.shape)

    def check_source(self, vertex: int) -> int:
        """``vertex`` if it has values (a face uses it or its vertex), else a ValueError."""
        if np.isnan(self.modes[vertex]).any():
            raise ValueError(_unused_words(vertex))
        return vertex

    def squared_modes(self, vertices=None) -> np.ndarray:
        """(n, k) |phi_j(v)|^2 (summed over xyz for vector modes), or only ``vertices``' rows."""
        modes = self.modes if vertices is None else self.modes[np.asarray(vertices, dtype=int)]
        if self.is_vector:
            return np.einsum("ick,ick->ik", modes, modes)
        return modes**2


def spectrum_arrays(spec: Spectrum) -> dict[str, np.ndarray]:
    """The arrays of ``spec``'s file: :data:`SPECTRUM_ARRAYS` and ``meta`` (JSON: format,
    operator, mesh hash, parameters)."""
    meta = {
        "format": "modalviewer-spectrum",
        "version": FORMAT_VERSION,
        "operator": spec.operator,
        "mesh_hash": spec.mesh_hash,
        "parameters": spec.parameters,
    }
    arrays = {name: getattr(spec, name) for name in SPECTRUM_ARRAYS}
    return {**arrays, "meta": np.array(json.dumps(meta))}


def save_spectrum(spec: Spectrum, path: str | os.PathLike) -> None:
    """Write ``spec`` to ``path`` as ``.npz`` (atomically: a half-written file never
    replaces a good one), with its mesh hash and parameters; an OSError if it cannot
    be written."""

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **spectrum_arrays(spec))

    atomic_write(Path(path), write, suffix=".part")


def load_spectrum(
    path: str | os.PathLike,
    mesh: Mesh | None = None,
    mesh_hash: str | None = None,
) -> Spectrum:
    """Read a spectrum written by :func:`save_spectrum`, checked to belong to ``mesh`` (or
    to the mesh of hash ``mesh_hash``) if given.  A :class:`SpectrumFileError` if the file
    is not a readable, consistent and finite spectrum file or belongs to another mesh; a
    TypeError if ``mesh`` is not a Mesh (pass a hash as ``mesh_hash=``) or both are given."""
    if mesh is not None:
        if not isinstance(mesh, Mesh):
            hint = f", got {type(mesh).__name__}"
            if isinstance(mesh, (str, bytes)):
                hint = "; to check against a hash string pass mesh_hash=..."
            raise TypeError("mesh must be a Mesh" + hint)
        if mesh_hash is not None:
            raise TypeError("pass mesh or mesh_hash, not both")
        mesh_hash = mesh.hash
    elif mesh_hash is not None and not isinstance(mesh_hash, str):
        raise TypeError(f"mesh_hash must be a string (mesh.hash), got {type(mesh_hash).__name__}")
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            arrays = {name: np.array(data[name], dtype=np.float64) for name in SPECTRUM_ARRAYS}
            spec = Spectrum(
                **arrays,
                operator=meta["operator"],
                mesh_hash=meta.get("mesh_hash", ""),
                parameters=meta.get("parameters", {}),
            )
    except FileNotFoundError:
        raise
    except Exception as exc:  # any damage: zip errors, missing keys, bad JSON
        raise SpectrumFileError(f"{path} is not a readable spectrum file ({exc})") from None
    if meta.get("format") != "modalviewer-spectrum" or spec.operator not in OPERATOR_INFO:
        raise SpectrumFileError(f"{path} is not a modalviewer spectrum file")
    k = spec.eigenvalues.shape[0]
    n = spec.mass.shape[0]
    expected = (n, 3, k) if spec.operator_info.unknowns_per_vertex == 3 else (n, k)
    if spec.modes.shape != expected or spec.residuals.shape != (k,):
        raise SpectrumFileError(f"{path} has inconsistent array shapes")
    valued = spec.mass > 0  # vertices no face uses have mass 0 and NaN modes
    if not all(np.isfinite(a).all() for a in (spec.eigenvalues, spec.modes[valued], spec.mass)):
        raise SpectrumFileError(f"{path} contains NaN or infinite values")
    if mesh_hash is not None and spec.mesh_hash != mesh_hash:
        raise SpectrumFileError(f"{path} belongs to another mesh")
    return spec


def in_input_numbering(spec: Spectrum, mesh: Mesh) -> Spectrum:
    """``spec``, computed on ``mesh.solver_mesh``, in ``mesh``'s numbering: NaN modes and
    zero mass at unused vertices, a merged vertex's modes those of its vertex (mass 0)."""
    solver = mesh.solver_mesh
    if solver is mesh:
        return spec
    mass = np.zeros(mesh.n_vertices)
    mass[solver.file_vertices] = spec.mass
    return replace(
        spec,
        modes=solver.to_file_field(spec.modes),
        mass=mass,
        mesh_hash=mesh.hash,
        parameters={**spec.parameters, "unused_vertices": int(mesh.unused.size)},
    )


class GrowingSpectrum:
    """The modes of a spectrum as they arrive, lowest first, in one array for all k;
    :meth:`so_far` views them as a :class:`Spectrum` (residuals NaN until it is whole)."""

    def __init__(self, k: int) -> None:
        self.k = int(k)
        self.count = 0
        self.eigenvalues = np.zeros(self.k)
        self.modes: np.ndarray | None = None  # (n, k) or (n, 3, k), made at the first

    def append(self, eigenvalues: np.ndarray, modes: np.ndarray) -> None:
        """The next modes: (m,) eigenvalues and their (n, m) or (n, 3, m) modes."""
        if self.modes is None:
            self.modes = np.empty(modes.shape[:-1] + (self.k,))
        j0, j1 = self.count, self.count + eigenvalues.shape[0]
        self.eigenvalues[j0:j1] = eigenvalues
        self.modes[..., j0:j1] = modes
        self.count = j1

    def so_far(self, operator: str, mass: np.ndarray, mesh_hash: str, parameters: dict):
        """A Spectrum of the modes in (``parameters`` plus ``modes_requested``)."""
        j = self.count
        return Spectrum(
            eigenvalues=self.eigenvalues[:j].copy(),
            modes=self.modes[..., :j],
            operator=operator,
            mass=mass,
            residuals=np.full(j, np.nan),
            mesh_hash=mesh_hash,
            parameters={**parameters, "modes_requested": self.k},
        )


def on_solver_mesh(spec: Spectrum, mesh: Mesh) -> Spectrum:
    """``spec`` of ``mesh.input_mesh`` (one row per input vertex) on ``mesh``, its solver
    mesh; ``spec`` itself where it is in that numbering already."""
    if mesh.input_mesh is mesh or spec.n_vertices == mesh.n_vertices:
        return spec
    if spec.mesh_hash and spec.mesh_hash != mesh.input_mesh.hash:
        return spec  # another mesh's: the caller's check says so
    rows = mesh.file_vertices
    return replace(spec, modes=spec.modes[rows], mass=spec.mass[rows], mesh_hash=mesh.hash)
