"""Displacement fields carried from a coarse copy to the mesh (core/transfer.py)."""

import numpy as np
import pytest

from modalviewer.core import transfer
from modalviewer.core.primitives import torus


@pytest.fixture(scope="module")
def pair():
    """A coarse torus and a fine one of the same surface: the fine vertices lie off the
    coarse triangles' planes (chords of a curved surface), as a mesh's do over its
    decimated copy."""
    return torus(24, 10, minor=0.25), torus(96, 40, minor=0.25)


def _brute_force_distances(coarse, points):
    f = coarse.faces
    x = coarse.vertices
    m, t = len(points), len(f)
    p = np.repeat(points, t, axis=0)
    a, b, c = (np.tile(x[f[:, i]], (m, 1)) for i in range(3))
    _, d = transfer._closest_on_triangles(p, a, b, c)
    return np.sqrt(d.reshape(m, t).min(axis=1))


def test_nearest_triangles_match_a_search_over_all_triangles(pair):
    coarse, fine = pair
    points = fine.vertices[::7]
    tri, bary = transfer.nearest_triangles(coarse, points)
    assert np.all(bary >= -1e-12) and np.allclose(bary.sum(axis=1), 1.0, atol=1e-12)
    nearest = np.einsum("ij,ijk->ik", bary, coarse.vertices[coarse.faces[tri]])
    found = np.linalg.norm(points - nearest, axis=1)
    np.testing.assert_allclose(found, _brute_force_distances(coarse, points), atol=1e-12)


def test_rigid_motions_are_carried_exactly_over_triangle_interiors(pair):
    coarse, fine = pair
    rng = np.random.default_rng(3)
    w, t = rng.standard_normal(3), rng.standard_normal(3)
    carried = (
        transfer.displacement_prolongation(coarse, fine)
        @ (np.cross(w, coarse.vertices) + t).ravel()
    )
    expected = np.cross(w, fine.vertices) + t
    _, bary = transfer.nearest_triangles(coarse, fine.vertices)
    interior = (bary > 1e-9).all(axis=1)  # nearest point inside a triangle: p - q along n
    assert interior.mean() > 0.5
    error = np.linalg.norm(carried.reshape(-1, 3) - expected, axis=1)
    assert error[interior].max() <= 1e-12 * np.linalg.norm(expected, axis=1).max()
    # without the normal offset term, barycentric interpolation does not carry rotations
    tri, bary = transfer.nearest_triangles(coarse, fine.vertices)
    plain = np.einsum("ij,ijk->ik", bary, (np.cross(w, coarse.vertices) + t)[coarse.faces[tri]])
    assert np.linalg.norm(plain - expected, axis=1)[interior].max() > 1e-3


def test_a_given_location_is_used_as_given(pair):
    coarse, fine = pair
    tri, bary = transfer.nearest_triangles(coarse, fine.vertices)
    searched = transfer.CoarseCopy(coarse).prolongation(fine)
    given = transfer.CoarseCopy(coarse, tri, bary).prolongation(fine)
    assert abs(searched - given).max() == 0.0
    assert searched.shape == (3 * fine.n_vertices, 3 * coarse.n_vertices)
    assert np.all(np.diff(searched.indptr) == 9)  # 3 corners x 3 components per row
