"""Distances between two shapes: a vertex of mesh A against every vertex of mesh B.

Eq. (31) with one signature from each mesh, each divided by its own mesh's
``Z(t) = sum_j exp(-lambda_j t)``, both sampled at the same scales:

``delta(v, w) = sqrt( sum_i ((S^A_{t_i}(v) / Z^A(t_i) - S^B_{t_i}(w) / Z^B(t_i))^2 * dlogt) )``

The common scales are those both truncated spectra resolve.  Signatures carry a factor
``1 / area`` (the shells spectrum is not even scale covariant), so compare meshes of the
same area (:func:`rescale_to_area`); a :class:`ScaleWarning` says when they differ.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .mesh import Mesh
from .signatures import SignatureTable, default_scales, log_spaced, normalised_signatures
from .spectrum import Spectrum
from .validate import check_count, check_t_range, check_vertex, check_vertices

TRange = Sequence[float] | np.ndarray | None
Vertices = int | Sequence[int] | np.ndarray

AREA_TOLERANCE = 0.05  # relative area difference above which a ScaleWarning is issued


class ScaleWarning(UserWarning):
    """The two meshes differ in area: their signatures are not on the same scale."""


def rescale_to_area(mesh: Mesh, area: float = 1.0) -> Mesh:
    """A copy of ``mesh`` scaled about the origin to the positive total ``area``."""
    area = float(area)
    if not (np.isfinite(area) and area > 0):
        raise ValueError(f"the target area must be a positive number, got {area}")
    factor = np.sqrt(area / mesh.total_area)
    return Mesh(
        mesh.vertices * factor,
        mesh.faces,
        report=mesh.report,
        file_map=mesh.file_map,
        merged_into=mesh.merged_into,
    )


def _check_pair(spec_a: Spectrum, spec_b: Spectrum) -> None:
    if spec_a.operator != spec_b.operator:
        raise ValueError(
            f"both spectra must come from the same operator, got {spec_a.operator!r} "
            f"and {spec_b.operator!r} (signatures of different operators are not comparable)"
        )
    for name in ("bending", "membrane") if spec_a.operator_info.has_weights else ():
        a, b = spec_a.parameters.get(name), spec_b.parameters.get(name)
        if a is not None and b is not None and a != b:
            raise ValueError(f"the two shells spectra use different {name} weights ({a} and {b})")
    area_a, area_b = float(spec_a.mass.sum()), float(spec_b.mass.sum())
    if abs(area_a - area_b) > AREA_TOLERANCE * max(area_a, area_b):
        warnings.warn(
            f"the meshes' areas differ ({area_a:.4g} and {area_b:.4g}); signatures scale "
            "with 1/area, so rescale both to the same area (rescale_to_area) to compare shapes",
            ScaleWarning,
            stacklevel=3,
        )


def common_times(
    spec_a: Spectrum,
    spec_b: Spectrum,
    t_range: TRange = None,
    samples: int = 100,
    kind: str = "heat",
) -> np.ndarray:
    """(samples,) log-spaced scales shared by both spectra: ``t_range`` if given, else
    the intersection of the two default ranges (of energies for ``kind="wks"``); a
    ValueError if those do not overlap (the meshes differ too much in size)."""
    samples = check_count(samples, "samples", 2)
    if t_range is None:
        ta, tb = default_scales(spec_a, 2, kind), default_scales(spec_b, 2, kind)
        t1, t2 = max(ta[0], tb[0]), min(ta[-1], tb[-1])
        if not t1 < t2:
            raise ValueError(
                f"the default scale ranges [{ta[0]:.4g}, {ta[-1]:.4g}] and "
                f"[{tb[0]:.4g}, {tb[-1]:.4g}] do not overlap: the meshes differ too much in "
                "size (rescale both to the same area) or pass t_range"
            )
    else:
        t1, t2 = check_t_range(t_range)
    return log_spaced(t1, t2, samples)


class CrossTables:
    """The normalised signature tables ``a``, ``b`` of A and B at the common scales
    ``times`` (:func:`common_times`; energies for ``kind="wks"``, so the wave kernels
    have the same width on both), for repeated queries."""

    def __init__(
        self,
        spec_a: Spectrum,
        spec_b: Spectrum,
        t_range: TRange = None,
        samples: int = 100,
        include_zero: bool = False,
        kind: str = "heat",
    ):
        _check_pair(spec_a, spec_b)
        times = common_times(spec_a, spec_b, t_range, samples, kind)
        t = (times[0], times[-1])
        self.times = times
        self.a = SignatureTable(spec_a, t, len(times), include_zero, kind=kind)
        self.b = SignatureTable(spec_b, t, len(times), include_zero, kind=kind)

    def a_to_b(self, vertex: int) -> np.ndarray:
        """(n_b,) distance from vertex ``vertex`` of A to every vertex of B."""
        return self.b.distance_to(self.a.row(vertex))

    def b_to_a(self, vertex: int) -> np.ndarray:
        """(n_a,) distance from vertex ``vertex`` of B to every vertex of A."""
        return self.a.distance_to(self.b.row(vertex))

    def mutual_best_matches(
        self, vertices_a: Vertices, vertices_b: Vertices | None = None
    ) -> Matches:
        """See :func:`mutual_best_matches`."""
        va = check_vertices(vertices_a, self.a.table.shape[0], "vertices_a")
        vb, among_a = None, None  # the searches run over every vertex, or over the picks
        if vertices_b is not None:
            vb, among_a = check_vertices(vertices_b, self.b.table.shape[0], "vertices_b"), va

        def nearest(d: np.ndarray, among: np.ndarray | None) -> int:
            return int(np.nanargmin(d)) if among is None else int(among[np.nanargmin(d[among])])

        rows = []
        for v in va:
            d = self.a_to_b(v)
            w = nearest(d, vb)
            rows.append((w, d[w], nearest(self.b_to_a(w), among_a)))
        matches_b, distances, back = (np.array(column) for column in zip(*rows, strict=True))
        return Matches(va, matches_b, distances, back, back == va)


@dataclass
class Matches:
    """Best matches of picked vertices of A on B, and back: for each of ``vertices_a``
    (p,), the closest vertex of B (``matches_b``) at ``distances``, the vertex of A
    closest to that (``back_matches_a``) and whether it is the picked one (``mutual``)."""

    vertices_a: np.ndarray
    matches_b: np.ndarray
    distances: np.ndarray
    back_matches_a: np.ndarray
    mutual: np.ndarray


def cross_distance(
    spec_a: Spectrum,
    vertex: int,
    spec_b: Spectrum,
    t_range: TRange = None,
    samples: int = 100,
    include_zero: bool = False,
) -> np.ndarray:
    """(n_b,) the distance of eq. (31) from vertex ``vertex`` of A to every vertex of B
    (NaN where no face uses it) over ``samples`` log-spaced scales in ``t_range``
    (default: :func:`common_times`).  A ValueError for spectra of different operators
    or weights, or default scale ranges that do not overlap."""
    v = spec_a.check_source(check_vertex(vertex, spec_a.n_vertices))
    _check_pair(spec_a, spec_b)
    times = common_times(spec_a, spec_b, t_range, samples)
    table_b = SignatureTable(spec_b, (times[0], times[-1]), len(times), include_zero)
    row = normalised_signatures(spec_a, table_b.times, include_zero, [v])[0]
    return table_b.distance_to(row)


def best_match(
    spec_a: Spectrum,
    vertex: int,
    spec_b: Spectrum,
    t_range: TRange = None,
    samples: int = 100,
    include_zero: bool = False,
) -> tuple[int, float]:
    """(vertex of B, distance): the vertex of B closest to vertex ``vertex`` of A under
    :func:`cross_distance` (whose arguments these are)."""
    d = cross_distance(spec_a, vertex, spec_b, t_range, samples, include_zero)
    w = int(np.nanargmin(d))  # vertices no face uses have no distance (NaN)
    return w, float(d[w])


def mutual_best_matches(
    spec_a: Spectrum,
    vertices_a: Vertices,
    spec_b: Spectrum,
    vertices_b: Vertices | None = None,
    t_range: TRange = None,
    samples: int = 100,
    include_zero: bool = False,
) -> Matches:
    """Best match on B of each picked vertex of A, and whether the match is mutual: for
    each ``v`` in ``vertices_a``, ``w`` the vertex of B closest to ``v`` and ``v'`` the
    vertex of A closest to ``w``; mutual if ``v' == v``.  With ``vertices_b`` the
    searches run over the two sets of picks only (matching landmarks).  ``t_range``,
    ``samples``, ``include_zero``: as for :func:`cross_distance`."""
    tables = CrossTables(spec_a, spec_b, t_range, samples, include_zero)
    return tables.mutual_best_matches(vertices_a, vertices_b)


def distance_ranks(distances: np.ndarray, vertices: Vertices) -> np.ndarray:
    """The rank of each of ``vertices`` in a distance map: 1 + the number of vertices
    strictly closer (rank 1 = best match, ties share the better rank): (m,) ints for
    ``vertices`` (m,) of the (n,) map ``distances``."""
    d = np.asarray(distances, dtype=np.float64)
    idx = check_vertices(vertices, d.shape[0])
    return 1 + np.sum(d[None, :] < d[idx, None], axis=1)
