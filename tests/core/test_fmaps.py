"""Functional maps on any scalar basis: the closed-form solve, the point map, ZoomOut, the
geodesic error, and a bent pose matched back to the identity."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core import fmaps
from modalviewer.core.demo_shapes import bent_pose
from modalviewer.core.primitives import icosphere


@pytest.fixture(scope="module")
def lumpy():
    """A sphere of 642 vertices with lumps of different sizes: no symmetry to confuse a
    map."""
    base = icosphere(3)
    x = base.vertices
    bumps = [
        ([1, 0, 0], 0.4),
        ([0, 1, 0], 0.25),
        ([0, 0, 1], 0.3),
        ([-0.6, -0.8, 0], 0.2),
        ([0.5, 0.4, -0.77], 0.15),
    ]
    r = 1.0 + sum(h * np.exp(-8 * np.sum((x - c) ** 2, axis=1)) for c, h in bumps)
    return mv.Mesh(x * r[:, None] * [1.6, 1.0, 0.8], base.faces)


def test_the_map_of_a_shape_to_itself_is_the_identity(lumpy):
    spec = mv.compute_spectrum(lumpy, "laplacian", k=30)
    for descriptors in ("wks", "hks"):
        fm = mv.functional_map(spec, spec, descriptors, k=20)
        assert fm.C.shape == (20, 20) and fm.k == 20
        np.testing.assert_allclose(np.abs(np.diag(fm.C)), 1.0, atol=1e-6)
        assert np.abs(fm.C - np.diag(np.diag(fm.C))).max() < 1e-6
        np.testing.assert_array_equal(fm.point_map, np.arange(lumpy.n_vertices))


def test_the_solve_is_the_minimiser():
    """Each row of C zeroes the gradient of |C A - B|^2 + mu sum C_ij^2 D_ij."""
    rng = np.random.default_rng(0)
    A, B = rng.normal(size=(8, 40)), rng.normal(size=(8, 40))
    la, lb = np.sort(rng.uniform(0, 5, 8)), np.sort(rng.uniform(0, 5, 8))
    C = fmaps.solve_map(A, B, la, lb, 0.7)
    D = (lb[:, None] - la[None, :]) ** 2
    D /= np.linalg.norm(D)
    gradient = 2 * (C @ A - B) @ A.T + 2 * 0.7 * D * C
    assert np.abs(gradient).max() < 1e-10 * np.abs(B @ A.T).max()


def test_a_bent_pose_is_matched_back_for_each_basis(lumpy):
    bent = bent_pose(lumpy, 30.0)  # 30 degrees over the middle 40 % of its length
    errors = {}
    for operator in ("laplacian", "modified_dirichlet", "shells_normal"):
        sa = mv.compute_spectrum(lumpy, operator, k=40)
        sb = mv.compute_spectrum(bent, operator, k=40)
        fm = mv.functional_map(sa, sb, "hks", k=20, zoomout=40)
        assert fm.C.shape == (40, 40)
        coarse = mv.functional_map(sa, sb, "hks", k=20, zoomout=40, zoomout_step=7)
        assert coarse.C.shape == (40, 40)  # 27, 34, then 40
        errors[operator] = float(np.mean(mv.correspondence_errors(lumpy, fm.point_map)))
    # a random map of this mesh is about 0.45 sqrt(area) off on average
    random = np.random.default_rng(1).integers(0, lumpy.n_vertices, lumpy.n_vertices)
    assert np.mean(mv.correspondence_errors(lumpy, random)) > 0.3
    assert max(errors.values()) < 0.1, errors


def test_correspondence_errors_are_edge_geodesics_over_sqrt_area():
    mesh = icosphere(2)
    e = mesh.edges[5]
    point_map = np.arange(mesh.n_vertices)
    point_map[e[0]] = e[1]  # one vertex sent to a neighbour
    errors = mv.correspondence_errors(mesh, point_map)
    length = np.linalg.norm(mesh.vertices[e[0]] - mesh.vertices[e[1]])
    assert errors[e[0]] == pytest.approx(length / np.sqrt(mesh.face_areas.sum()), rel=1e-12)
    assert np.count_nonzero(errors) == 1
    assert len(mv.correspondence_errors(mesh, point_map, every=10)) == len(range(0, 162, 10))


def test_bad_requests_say_what_is_wrong(lumpy):
    spec = mv.compute_spectrum(lumpy, "laplacian", k=10)
    shells = mv.compute_spectrum(lumpy, "shells", k=10)
    with pytest.raises(ValueError, match="vector modes"):
        mv.functional_map(shells, shells, k=5)
    with pytest.raises(ValueError, match="at least 20"):
        mv.functional_map(spec, spec, k=20)
    with pytest.raises(ValueError, match="unknown descriptors"):
        mv.functional_map(spec, spec, "sihks", k=5)
    with pytest.raises(ValueError, match="descriptors must be arrays"):
        mv.functional_map(spec, spec, (np.ones((3, 2)), np.ones((3, 2))), k=5)
    small = mv.Mesh(lumpy.vertices * 0.01, lumpy.faces)
    with pytest.raises(ValueError, match="do not overlap"):
        mv.functional_map(spec, mv.compute_spectrum(small, "laplacian", k=10), k=5)
