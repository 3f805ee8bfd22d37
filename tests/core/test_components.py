"""Meshes of several components: the largest one, spectra per component."""

import numpy as np
import pytest
import scipy.linalg as la

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.primitives import icosphere, torus


@pytest.fixture(scope="module")
def parts():
    """A torus (the largest area), a sphere and a small sphere, interleaved in the files'
    vertex order: the sphere first."""
    s, t = icosphere(2), torus(20, 10, 1.0, 0.4)
    small = mv.Mesh(0.2 * s.vertices + [0, 0, 3.0], s.faces)
    t = mv.Mesh(t.vertices + [4.0, 0, 0], t.faces)
    v = np.vstack([s.vertices, t.vertices, small.vertices])
    f = np.vstack([s.faces, t.faces + 162, small.faces + 362])
    return mv.Mesh(v, f)


def test_largest_component_by_area_with_a_report(parts):
    kept = mv.largest_component(parts)
    assert (kept.n_vertices, kept.n_faces, kept.n_components) == (524, 400, 1)
    # the input's numbering: the other components' vertices are used by no face
    np.testing.assert_array_equal(kept.vertices, parts.vertices)
    np.testing.assert_array_equal(kept.unused, np.r_[0:162, 362:524])
    np.testing.assert_array_equal(kept.solver_mesh.vertices, parts.vertices[162:362])
    text = str(kept.report)
    assert "Kept the largest of 3 connected components (200 vertices" in text
    assert "removed 2 components with 324 vertices and 640 faces" in text
    one = mv.largest_component(kept)
    assert one.solver_mesh.n_vertices == 200 and "one connected component" in str(one.report)


def test_split_components_keeps_vertex_order(parts):
    pieces = mv.split_components(parts)
    assert [m.n_vertices for m, _ in pieces] == [200, 162, 162]
    for piece, vertices in pieces:
        np.testing.assert_array_equal(piece.vertices, parts.vertices[vertices])
    assert pieces[2][1][0] == 362  # the small sphere, last by area


@pytest.mark.parametrize("operator", ["laplacian", "shells"])
def test_spectra_per_component_are_the_whole_mesh_spectrum(parts, operator):
    per = mv.compute_spectrum_per_component(parts, operator, k=12)
    assert [c.mesh.n_vertices for c in per] == [200, 162, 162]
    null = 1 if operator == "laplacian" else 6
    K, mass = operator_matrices(parts, operator)
    whole = la.eigh(K.toarray(), np.diag(mass), eigvals_only=True)
    for c in per:
        spec = c.spectrum
        assert spec.null_space_dimension == null
        assert np.all(spec.eigenvalues[:null] == 0.0)
        # each component's eigenvalues are eigenvalues of the whole mesh
        for lam in spec.eigenvalues[null:]:
            assert np.min(np.abs(whole - lam)) < 1e-9 * lam
        # and the modes, zero on the other components, are the whole mesh's
        # eigenvectors, Mass-normalised (its operator is block diagonal)
        mode = spec.mode(null)
        lifted = np.zeros((parts.n_vertices, *mode.shape[1:]))
        lifted[c.vertices] = mode
        x = lifted.ravel()
        lam = spec.eigenvalues[null]
        r = K @ x - lam * mass * x
        assert np.linalg.norm(r) < 1e-8 * lam * np.linalg.norm(mass * x)
        assert abs(x @ (mass * x) - 1.0) < 1e-10


def test_per_component_progress_and_small_parts_left_out(parts):
    seen = []
    per = mv.compute_spectrum_per_component(
        parts, "laplacian", k=5, progress=lambda s, f: seen.append(f), min_vertices=170
    )
    assert len(per) == 1 and per[0].mesh.n_vertices == 200
    assert seen[-1] == pytest.approx(1.0) and all(0.0 <= f <= 1.0 for f in seen)
    with pytest.raises(ValueError, match="no component"):
        mv.compute_spectrum_per_component(parts, "laplacian", min_vertices=10**6)


def test_the_largest_components_report_begins_with_its_own_shape(parts):
    # it began with the input's "... 3 components ..." sentence
    loaded = mv.as_mesh((parts.vertices, parts.faces))
    assert str(loaded.report).startswith("arrays: 524 vertices, 1040 faces, 3 components")
    kept = mv.largest_component(loaded)
    text = str(kept.report)
    assert text.startswith(
        "arrays: 524 vertices (324 used by no face), 400 faces, 1 component, closed."
    ), text
    assert "3 components" not in text and "Kept the largest of 3 connected components" in text


def test_a_part_joined_at_a_single_vertex_is_reported_with_its_zero_modes():
    # two spheres sharing one vertex: one component, but the second can turn about the
    # shared vertex (3 more zero modes of the 3D shells), which the report did not say
    s = icosphere(1)
    v, f = np.array(s.vertices), np.array(s.faces)
    top, bottom = int(v[:, 2].argmax()), int(v[:, 2].argmin())
    second = f + len(v)
    second[second == bottom + len(v)] = top
    mesh = mv.as_mesh((np.vstack([v, v - v[bottom] + v[top]]), np.vstack([f, second])))
    assert mesh.n_components == 1 and mesh.n_face_components == 2
    assert "1 part joined to the rest only at a vertex" in str(mesh.report)
    spec = mv.compute_spectrum(mesh, "shells", 12)
    assert int(spec.zero_mode_mask().sum()) == 6 + 3
