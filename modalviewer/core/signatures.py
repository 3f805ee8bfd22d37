"""Multi-scale signatures and the distance of eq. (31) (paper Section 6).

``kind="heat"``: ``S_t(v) = sum_j exp(-lambda_j t) |phi_j(v)|^2``, the heat kernel
(Laplacian), feature (E_D^N) or vibration (3D shells) signature; zero modes left out by
default.  ``kind="wks"``: the wave kernel signature of Aubry, Schlickewei and Cremers
(2011), a band-pass filter in log-eigenvalue over the non-zero modes,
``W_E(v) = sum_j g_j(E) |phi_j(v)|^2 / sum_j g_j(E)`` with
``g_j(E) = exp(-(log E - log lambda_j)^2 / (2 sigma^2))``; its distance is eq. (31) over
log-energies (docs/conventions.md).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .mesh import _unused_words
from .spectrum import Spectrum
from .validate import check_count, check_t_range, check_times, check_vertex, check_vertices

WKS_VARIANCE = 7.0
"""The wave kernel's sigma in units of the log-energy spacing (Aubry et al.'s choice)."""


def _check_kind(kind: str) -> str:
    if kind not in ("heat", "wks"):
        raise ValueError(f"unknown signature kind {kind!r}; choose one of 'heat', 'wks'")
    return kind


def _used(spec: Spectrum, include_zero: bool) -> np.ndarray:
    mask = np.ones(spec.k, dtype=bool) if include_zero else ~spec.zero_mode_mask()
    if not mask.any():
        raise ValueError("the spectrum has no non-zero modes; compute more modes")
    return mask


def log_spaced(start: float, stop: float, samples: int) -> np.ndarray:
    """``samples`` values log-spaced from ``start`` to ``stop``: every scale range's grid
    (np.geomspace differs in the last digits)."""
    return np.exp(np.linspace(np.log(start), np.log(stop), samples))


def default_times(spec: Spectrum, samples: int = 100) -> np.ndarray:
    """``samples`` log-spaced scales from ``4 ln 10`` over the largest to over the
    smallest non-zero eigenvalue (with or without the zero modes in the signature)."""
    samples = check_count(samples, "samples", 2)
    lam = spec.eigenvalues[_used(spec, False)]
    return log_spaced(4.0 * np.log(10.0) / lam.max(), 4.0 * np.log(10.0) / lam.min(), samples)


def default_energies(spec: Spectrum, samples: int = 100) -> np.ndarray:
    """``samples`` energies of the wave kernel signature, log-spaced from the smallest to
    the largest non-zero eigenvalue (Aubry et al.'s band)."""
    samples = check_count(samples, "samples", 2)
    lam = _positive_eigenvalues(spec)
    return log_spaced(lam.min(), lam.max(), samples)


def default_scales(spec: Spectrum, samples: int = 100, kind: str = "heat") -> np.ndarray:
    """:func:`default_energies` for ``kind="wks"``, else :func:`default_times`."""
    return (default_energies if kind == "wks" else default_times)(spec, samples)


def wks_sigma(energies: Sequence[float] | np.ndarray) -> float:
    """The wave kernel's width in log-energy: :data:`WKS_VARIANCE` times the spacing of
    ``log(energies)`` (for one energy, times 0.05)."""
    e = np.log(check_times(energies, "energies"))
    if e.size < 2 or e.max() == e.min():
        return WKS_VARIANCE * 0.05
    return WKS_VARIANCE * float(e.max() - e.min()) / (e.size - 1)


def _positive_eigenvalues(spec: Spectrum) -> np.ndarray:
    lam = spec.eigenvalues[_used(spec, False)]
    if lam.min() <= 0:
        raise ValueError(
            f"the wave kernel signature needs positive eigenvalues; this spectrum has "
            f"{lam.min():.3g}"
        )
    if lam.max() == lam.min():
        raise ValueError("the wave kernel signature needs two distinct non-zero eigenvalues")
    return lam


def signature(
    spec: Spectrum,
    times: float | Sequence[float] | np.ndarray | None = None,
    include_zero: bool = False,
    vertices: int | Sequence[int] | np.ndarray | None = None,
    kind: str = "heat",
    energies: float | Sequence[float] | np.ndarray | None = None,
    sigma: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(times (T,), values (n, T))``: the signature at every vertex (or only the rows
    of ``vertices``; NaN where no face uses one) and positive scale ``times`` (default
    :func:`default_times`), with or without the zero modes.  ``kind="wks"``: ``W_E(v)``
    at ``energies`` (default :func:`default_energies`) of width ``sigma`` in log-energy
    (default :func:`wks_sigma`) instead (module docstring)."""
    if vertices is not None:
        vertices = check_vertices(vertices, spec.n_vertices, allow_empty=True)
    if _check_kind(kind) == "wks":
        if times is not None or include_zero:
            raise ValueError(
                "the wave kernel signature takes energies=, over the non-zero modes "
                "(no times or include_zero)"
            )
        energies = default_energies(spec) if energies is None else check_times(energies, "energies")
        sigma = wks_sigma(energies) if sigma is None else float(sigma)
        if not (np.isfinite(sigma) and sigma > 0):
            raise ValueError(f"sigma must be positive and finite, got {sigma!r}")
        gap = np.log(energies)[None, :] - np.log(_positive_eigenvalues(spec))[:, None]
        weights = np.exp(-(gap**2) / (2.0 * sigma**2))  # (k', T) over the non-zero modes
        squared = spec.squared_modes(vertices)[:, ~spec.zero_mode_mask()]
        return energies, (squared @ weights) / weights.sum(axis=0)
    if energies is not None or sigma is not None:
        raise ValueError('energies= and sigma= belong to kind="wks"')
    mask = _used(spec, include_zero)
    times = check_times(default_times(spec) if times is None else times)
    lam = spec.eigenvalues[mask]
    weights = np.exp(-np.outer(lam, times))  # (k, T)
    return times, spec.squared_modes(vertices)[:, mask] @ weights


def normalised_signatures(
    spec: Spectrum, times, include_zero: bool = False, vertices=None, kind: str = "heat"
):
    """(n, T), or (len(vertices), T): ``S_t(v) / Z(t) * sqrt(dlogt)`` at the log-spaced
    ``times``, the rows whose Euclidean distances are eq. (31)'s Riemann sum; for
    ``kind="wks"`` ``W_E(v) * sqrt(dlogE)`` at the log-spaced energies ``times``."""
    times = np.asarray(times, dtype=np.float64)
    dlogt = (np.log(times[-1]) - np.log(times[0])) / (len(times) - 1)
    if _check_kind(kind) == "wks":
        return signature(spec, kind="wks", energies=times, vertices=vertices)[1] * np.sqrt(dlogt)
    z = np.exp(-np.outer(spec.eigenvalues[_used(spec, include_zero)], times)).sum(axis=0)
    return signature(spec, times, include_zero, vertices)[1] / z * np.sqrt(dlogt)


class SignatureTable:
    """Normalised signatures of all vertices for fast distance queries: ``table`` (n, T)
    ``F = S_t(v) / Z(t) * sqrt(dlogt)`` at the scales ``times``, so ``delta(v, w) =
    |F[v] - F[w]|`` (``kind="wks"``: ``W_E(v) sqrt(dlogE)`` at energies).  ``t_range``
    is the range asked for (None: the default range).  O(n T) per query."""

    def __init__(
        self,
        spec: Spectrum,
        t_range: Sequence[float] | np.ndarray | None = None,
        samples: int = 100,
        include_zero: bool = False,
        kind: str = "heat",
    ):
        samples = check_count(samples, "samples", 2)
        self.kind = _check_kind(kind)
        if kind == "wks" and include_zero:
            raise ValueError("the wave kernel signature leaves the zero modes out")
        self.t_range = None if t_range is None else check_t_range(t_range)
        if self.t_range is not None:
            self.times = log_spaced(*self.t_range, samples)
        else:
            self.times = default_scales(spec, samples, kind)
        self.table = normalised_signatures(spec, self.times, include_zero, kind=kind)
        self._norms2 = np.einsum("ij,ij->i", self.table, self.table)  # (n,) squared row norms

    def distance_from(self, vertex: int) -> np.ndarray:
        """(n,) distance from ``vertex`` to every vertex: one matrix-vector product by
        ``|F[v] - F[w]|^2 = |F[v]|^2 + |F[w]|^2 - 2 F[v].F[w]``, the entries where that
        cancels recomputed directly, so d(v, v) = 0 exactly."""
        return self.distance_to(self.row(vertex))

    def row(self, vertex: int) -> np.ndarray:
        """The normalised signature of ``vertex``; a ValueError if no face uses it."""
        row = self.table[check_vertex(vertex, self.table.shape[0])]
        if np.isnan(row).any():
            raise ValueError(_unused_words(int(vertex)))
        return row

    def distance_to(self, row: np.ndarray) -> np.ndarray:
        """(n,) distance from a normalised signature ``row`` (T,) sampled at the same
        :attr:`times` to every vertex (another mesh's row: :mod:`.cross`)."""
        row = np.asarray(row, dtype=np.float64)
        if row.shape != (self.table.shape[1],):
            raise ValueError(f"row must have shape ({self.table.shape[1]},), got {row.shape}")
        norm2 = float(row @ row)
        d2 = self._norms2 + norm2 - 2.0 * (self.table @ row)
        close = np.flatnonzero(d2 <= 1e-6 * (self._norms2 + norm2))
        diff = self.table[close] - row
        d2[close] = np.einsum("ij,ij->i", diff, diff)
        return np.sqrt(np.maximum(d2, 0.0))


def multiscale_distance(
    spec: Spectrum,
    vertex: int,
    t_range: Sequence[float] | np.ndarray | None = None,
    samples: int = 100,
    include_zero: bool = False,
    kind: str = "heat",
) -> np.ndarray:
    """(n,) the multi-scale distance of eq. (31) from ``vertex`` to every vertex (NaN
    where no face uses it): a Riemann sum over ``samples`` log-spaced scales in
    ``t_range`` (default: :func:`default_times`' or, for ``kind="wks"``,
    :func:`default_energies`' range) of signature differences normalised by ``Z(t)``."""
    vertex = spec.check_source(check_vertex(vertex, spec.n_vertices))
    table = SignatureTable(spec, t_range, samples, include_zero, kind=kind)
    return table.distance_from(vertex)
