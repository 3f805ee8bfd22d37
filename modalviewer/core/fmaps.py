"""Functional maps (Ovsjanikov et al. 2012) on the modes of any scalar operator.

A functional map ``C`` (k_b, k_a) takes a function on shape A, written in A's first
``k_a`` modes, to its coefficients in B's first ``k_b`` modes.  From descriptors that
should agree on corresponding points (wave or heat kernel signatures, or your own),
projected on the modes as ``A = Phi_a^T M_a F_a`` and ``B = Phi_b^T M_b F_b`` (each
column of unit M-norm), it solves row by row in closed form

    C = argmin |C A - B|^2 + mu sum_ij C_ij^2 (lambda^b_i - lambda^a_j)^2 / s,

``s`` the Frobenius norm of the squared eigenvalue differences (as pyFM).  The point map
sends vertex y of B to the vertex x of A with ``Phi_a[x]`` nearest ``Phi_b[y] C``;
``zoomout`` refines it by ZoomOut (Melzi et al. 2019).  Any scalar operator's modes
serve (Laplacian, E_D^N, normal shells); the 3D shells' vector modes are refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from .cross import common_times
from .signatures import signature
from .spectrum import Spectrum
from .validate import check_count


@dataclass
class FunctionalMap:
    """The result of :func:`functional_map`: ``C`` (k, k) the functional map from A's
    modes to B's (after ZoomOut: of its final size), ``point_map`` (n_b,) each vertex of
    B's vertex of A (-1 where no face uses B's vertex)."""

    C: np.ndarray
    point_map: np.ndarray
    k: int


def _scalar_basis(spec: Spectrum, k: int, which: str) -> tuple[np.ndarray, np.ndarray]:
    if spec.is_vector:
        raise ValueError(
            f"spectrum {which} has vector modes ({spec.operator}); a functional map needs a "
            "basis of functions: the Laplacian, modified_dirichlet or shells_normal modes"
        )
    if spec.k < k:
        raise ValueError(f"spectrum {which} has {spec.k} modes; k={k} needs at least {k}")
    return spec.modes[:, :k], spec.mass > 0  # the rows of vertices faces use


def _descriptors(spec_a, spec_b, descriptors, samples: int):
    if isinstance(descriptors, str):
        if descriptors not in ("wks", "hks"):
            raise ValueError(
                f"unknown descriptors {descriptors!r}; choose 'wks', 'hks' or pass a pair of "
                "arrays (n_a, d), (n_b, d)"
            )
        kind = "wks" if descriptors == "wks" else "heat"
        scales = common_times(spec_a, spec_b, samples=samples, kind=kind)
        at = {"kind": "wks", "energies": scales} if kind == "wks" else {"times": scales}
        return tuple(signature(s, **at)[1] for s in (spec_a, spec_b))
    fa, fb = (np.asarray(f, dtype=np.float64) for f in descriptors)
    if fa.ndim == 1:
        fa, fb = fa[:, None], fb[:, None]
    if fa.shape != (spec_a.n_vertices, fa.shape[1]) or fb.shape != (spec_b.n_vertices, fa.shape[1]):
        raise ValueError(
            f"descriptors must be arrays ({spec_a.n_vertices}, d) and ({spec_b.n_vertices}, d), "
            f"got {fa.shape} and {fb.shape}"
        )
    return fa, fb


def _project(phi: np.ndarray, mass: np.ndarray, used: np.ndarray, f: np.ndarray) -> np.ndarray:
    """(k, d): each descriptor column scaled to unit M-norm, then ``Phi^T M f``."""
    f, phi, m = f[used], phi[used], mass[used]
    norms = np.sqrt(m @ f**2)
    f = f / np.where(norms > 0, norms, 1.0)
    return phi.T @ (m[:, None] * f)


def solve_map(A: np.ndarray, B: np.ndarray, lam_a, lam_b, mu: float) -> np.ndarray:
    """The C minimising ``|C A - B|^2 + mu sum_ij C_ij^2 D_ij`` (module docstring), row by
    row: ``C_i (A A^T + mu diag(D_i)) = B_i A^T``."""
    D = (np.asarray(lam_b)[:, None] - np.asarray(lam_a)[None, :]) ** 2
    scale = np.linalg.norm(D)
    D = D / scale if scale > 0 else D
    AAt, BAt = A @ A.T, B @ A.T
    C = np.empty((len(lam_b), len(lam_a)))
    for i in range(len(lam_b)):
        C[i] = np.linalg.solve(AAt + mu * np.diag(D[i]), BAt[i])
    return C


def _nearest(points: np.ndarray, queries: np.ndarray) -> np.ndarray:
    """Index of the nearest row of ``points`` for each row of ``queries``: a k-d tree in
    few dimensions, else by blocks of ``|p|^2 - 2 p.q`` (k-d trees slow down past about
    ten dimensions, the blocks' matrix products do not)."""
    if points.shape[1] <= 8:
        return cKDTree(points).query(queries)[1]
    norms = np.einsum("ij,ij->i", points, points)
    out = np.empty(len(queries), dtype=np.int64)
    block = max(1, 2**22 // max(len(points), 1))
    for start in range(0, len(queries), block):
        q = queries[start : start + block]
        out[start : start + block] = np.argmin(norms[None, :] - 2.0 * (q @ points.T), axis=1)
    return out


def point_map(C: np.ndarray, phi_a, phi_b, used_a, used_b) -> np.ndarray:
    """(n_b,) for each vertex y of B the vertex x of A whose modes ``Phi_a[x]`` are
    nearest ``Phi_b[y] C`` (the row y of ``Phi_b C``, which a point map ``Pi`` makes
    ``Phi_a[T(y)]``); -1 where y is used by no face."""
    kb, ka = C.shape
    rows_a = np.flatnonzero(used_a)
    out = np.full(phi_b.shape[0], -1, dtype=np.int64)
    out[used_b] = rows_a[_nearest(phi_a[rows_a, :ka], phi_b[used_b, :kb] @ C)]
    return out


def functional_map(
    spec_a: Spectrum,
    spec_b: Spectrum,
    descriptors="wks",
    k: int = 30,
    mu: float = 1.0,
    samples: int = 100,
    zoomout: int | None = None,
    zoomout_step: int = 1,
) -> FunctionalMap:
    """The functional map from A to B in their first ``k`` modes, and the point map of
    B's vertices to A's (module docstring), for spectra of one scalar operator on two
    shapes of about the same area.

    ``descriptors``: "wks" (wave kernel signatures at ``samples`` shared energies),
    "hks" (heat-type signatures at shared scales), or per-vertex arrays ((n_a, d),
    (n_b, d)).  ``mu``: the weight of the commutativity with the eigenvalues; the wave
    kernel descriptors need about 1 (pyFM's 1e-3 leaves C far from diagonal), the heat
    kernel's hardly depend on it.  ``zoomout``: refine by ZoomOut up to this many modes,
    ``zoomout_step`` per step (1 as in the paper).
    """
    k = check_count(k, "k", 1)
    final = k if zoomout is None else check_count(zoomout, "zoomout", k)
    phi_a, used_a = _scalar_basis(spec_a, final, "A")
    phi_b, used_b = _scalar_basis(spec_b, final, "B")
    fa, fb = _descriptors(spec_a, spec_b, descriptors, check_count(samples, "samples", 2))
    A = _project(phi_a[:, :k], spec_a.mass, used_a, fa)
    B = _project(phi_b[:, :k], spec_b.mass, used_b, fb)
    C = solve_map(A, B, spec_a.eigenvalues[:k], spec_b.eigenvalues[:k], float(mu))
    p2p = point_map(C, phi_a, phi_b, used_a, used_b)
    step = check_count(zoomout_step, "zoomout_step", 1)
    sizes = list(range(k + step, final, step)) + ([final] if final > k else [])
    for size in sizes:
        # ZoomOut: the map of the point map, pulled back in one more mode, C = Phi_b^+ Pi Phi_a
        rows = np.flatnonzero(used_b)
        mb = spec_b.mass[rows]
        C = phi_b[rows, :size].T @ (mb[:, None] * phi_a[p2p[rows], :size])
        p2p = point_map(C, phi_a, phi_b, used_a, used_b)
    return FunctionalMap(C, p2p, C.shape[0])


def correspondence_errors(
    mesh_a, point_map: np.ndarray, truth: np.ndarray | None = None, every: int = 1
) -> np.ndarray:
    """Geodesic errors of a point map of B's vertices to A's: for every ``every``-th vertex
    y of B, the distance on A between ``point_map[y]`` and ``truth[y]`` (default: y, two
    poses of one mesh) along A's edges (Dijkstra, a little above the geodesic distance),
    over sqrt(area of A): (ceil(n_b / every),), NaN where y has no image."""
    point_map = np.asarray(point_map, dtype=np.int64)
    truth = np.arange(len(point_map)) if truth is None else np.asarray(truth, dtype=np.int64)
    ys = np.arange(0, len(point_map), check_count(every, "every", 1))
    edges = mesh_a.edges
    lengths = np.linalg.norm(mesh_a.vertices[edges[:, 0]] - mesh_a.vertices[edges[:, 1]], axis=1)
    n = mesh_a.n_vertices
    graph = coo_matrix((lengths, (edges[:, 0], edges[:, 1])), shape=(n, n)).tocsr()
    mapped = point_map[ys]
    errors = np.full(len(ys), np.nan)
    block = max(1, 2**22 // max(n, 1))  # rows of distances held at once: 32 MB
    for start in range(0, len(ys), block):
        part = slice(start, start + block)
        sources, inverse = np.unique(truth[ys[part]], return_inverse=True)
        distances = dijkstra(graph, directed=False, indices=sources)
        errors[part] = distances[inverse, np.maximum(mapped[part], 0)]
    errors[mapped < 0] = np.nan
    return errors / np.sqrt(float(mesh_a.face_areas.sum()))
