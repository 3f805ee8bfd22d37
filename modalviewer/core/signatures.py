"""Multi-scale signatures and the distance of eq. (31) (paper Section 6).

The heat kernel signature (Laplacian modes), the feature signature (E_D^N modes) and
the vibration signature (3-vector shells modes) share one formula,
``S_t(v) = sum_j exp(-lambda_j t) |phi_j(v)|^2``; zero modes are left out by default.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .spectrum import Spectrum
from .validate import check_count, check_t_range, check_times, check_vertex, check_vertices

__all__ = ["default_times", "signature", "multiscale_distance", "SignatureTable"]


def _used(spec: Spectrum, include_zero: bool) -> np.ndarray:
    mask = np.ones(spec.k, dtype=bool) if include_zero else ~spec.zero_mode_mask()
    if not mask.any():
        raise ValueError("the spectrum has no non-zero modes; compute more modes")
    return mask


def default_times(spec: Spectrum, samples: int = 100, include_zero: bool = False) -> np.ndarray:
    """Log-spaced scales from ``4 ln 10 / lambda_max`` to ``4 ln 10 / lambda_min`` (the
    largest and the smallest non-zero eigenvalue used).

    Parameters
    ----------
    spec : Spectrum
        The spectrum whose eigenvalues set the range.
    samples : int
        The number of scales T.
    include_zero : bool
        Whether zero modes count (they do not change the range).

    Returns
    -------
    ndarray, shape (T,)
        The scales, ascending.

    Raises
    ------
    ValueError
        If the spectrum has no non-zero modes.
    """
    samples = check_count(samples, "samples", 2)
    lam = spec.eigenvalues[~spec.zero_mode_mask()]
    if lam.size == 0:
        raise ValueError("the spectrum has no non-zero modes; compute more modes")
    t1 = 4.0 * np.log(10.0) / lam.max()
    t2 = 4.0 * np.log(10.0) / lam.min()
    return np.exp(np.linspace(np.log(t1), np.log(t2), samples))


def signature(
    spec: Spectrum,
    times: float | Sequence[float] | np.ndarray | None = None,
    include_zero: bool = False,
    vertices: int | Sequence[int] | np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The signature ``sum_j exp(-lambda_j t) |phi_j(v)|^2`` at every vertex (or at
    ``vertices``) and scale: the heat kernel signature for the Laplacian, the feature
    signature for E_D^N, the vibration signature for the Discrete Shells.

    Parameters
    ----------
    spec : Spectrum
        The spectrum, n vertices.
    times : float or array_like of float, optional
        Positive, finite scales (default: :func:`default_times`).
    include_zero : bool
        Whether the sum includes the zero modes.
    vertices : int or array_like of int, optional
        Vertex indices in ``0..n-1`` (default: every vertex); the rows of vertices no
        face uses are NaN.

    Returns
    -------
    times : ndarray, shape (T,)
        The scales.
    values : ndarray, shape (n, T) or (len(vertices), T)
        The signature of each vertex at each scale.

    Raises
    ------
    TypeError, ValueError, IndexError
        For scales that are not positive and finite, or vertices that are not integer
        indices of the mesh.
    """
    mask = _used(spec, include_zero)
    times = default_times(spec, include_zero=include_zero) if times is None else times
    times = check_times(times)
    if vertices is not None:
        vertices = check_vertices(vertices, spec.n_vertices, allow_empty=True)
    lam = spec.eigenvalues[mask]
    weights = np.exp(-np.outer(lam, times))  # (k, T)
    values = spec.squared_modes(vertices)[:, mask] @ weights
    return times, values


def normalised_signatures(spec: Spectrum, times, include_zero: bool = False, vertices=None):
    """(n, T), or (len(vertices), T): ``S_t(v) / Z(t) * sqrt(dlogt)`` at the log-spaced
    ``times``, the rows whose Euclidean distances are eq. (31)'s Riemann sum."""
    mask = _used(spec, include_zero)
    times = np.asarray(times, dtype=np.float64)
    dlogt = (np.log(times[-1]) - np.log(times[0])) / (len(times) - 1)
    weights = np.exp(-np.outer(spec.eigenvalues[mask], times))  # (k, T)
    z = weights.sum(axis=0)  # (T,)
    return (spec.squared_modes(vertices)[:, mask] @ (weights / z)) * np.sqrt(dlogt)


class SignatureTable:
    """Normalised signatures of all vertices, ready for fast distance queries.

    Holds ``F = S_t(v) / Z(t) * sqrt(dlogt)`` as (n, T) so that
    ``delta(v, w) = |F[v] - F[w]|``.  Building costs one (n, k) x (k, T) product;
    each query then costs O(n T).
    """

    def __init__(
        self,
        spec: Spectrum,
        t_range: Sequence[float] | np.ndarray | None = None,
        samples: int = 100,
        include_zero: bool = False,
    ):
        samples = check_count(samples, "samples", 2)
        self.t_range = None if t_range is None else check_t_range(t_range)
        """The scale range asked for (None: the default range, see :attr:`times`)."""
        if self.t_range is None:
            times = default_times(spec, samples, include_zero)
        else:
            t1, t2 = self.t_range
            times = np.exp(np.linspace(np.log(t1), np.log(t2), samples))
        self.times = times
        self.table = normalised_signatures(spec, times, include_zero)

    @property
    def table(self) -> np.ndarray:
        """(n, T) normalised signatures."""
        return self._table

    @table.setter
    def table(self, value: np.ndarray) -> None:
        self._table = value
        self._norms2 = np.einsum("ij,ij->i", value, value)  # (n,) squared row norms

    def distance_from(self, vertex: int) -> np.ndarray:
        """(n,) distance from ``vertex`` to every vertex.

        ``|F[v] - F[w]|^2 = |F[v]|^2 + |F[w]|^2 - 2 F[v].F[w]``: one pass over the table
        (a matrix-vector product) instead of three.  Where that difference cancels
        (distance below 1e-3 of the signature norms) the entries are recomputed directly,
        so near-zero distances keep full relative accuracy and d(v, v) = 0 exactly.
        """
        row = self.table[check_vertex(vertex, self.table.shape[0])]
        if np.isnan(row).any():
            from .mesh import _unused_words

            raise ValueError(_unused_words(vertex))
        return self.distance_to(row)

    def distance_to(self, row: np.ndarray) -> np.ndarray:
        """(n,) distance from a normalised signature ``row`` (T,) to every vertex.

        ``row`` must be sampled at the same :attr:`times`, for example a row of another
        mesh's table (the distance between shapes of :mod:`modalviewer.core.cross`).
        """
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
) -> np.ndarray:
    """The multi-scale distance ``delta_[t1,t2](vertex, w)`` of eq. (31) to every vertex w.

    A Riemann sum over ``samples`` log-spaced scales in ``t_range``, each difference of
    signatures normalised by ``Z(t) = sum_j exp(-lambda_j t)``.

    Parameters
    ----------
    spec : Spectrum
        The spectrum, n vertices.
    vertex : int
        The vertex the distances are measured from.
    t_range : (float, float), optional
        The scales (t1, t2) (default: the range of :func:`default_times`).
    samples : int
        The number of scales of the sum.
    include_zero : bool
        Whether the signatures include the zero modes.

    Returns
    -------
    ndarray, shape (n,)
        The distance from ``vertex`` to each vertex (0 at ``vertex`` itself; NaN at the
        vertices no face uses).

    Raises
    ------
    ValueError
        If the spectrum has no non-zero modes, or no face uses ``vertex``.
    """
    vertex = spec.check_source(check_vertex(vertex, spec.n_vertices))
    return SignatureTable(spec, t_range, samples, include_zero).distance_from(vertex)
