"""One vertex numbering, the input's: vertex i of a mesh is row i of the arrays (or the
i-th vertex record of the file) it was made from, whatever no face uses or was merged,
and every per-vertex result has one row per input vertex."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.cleaning import repair_mesh
from modalviewer.core.components import largest_component, split_components
from modalviewer.core.cross import rescale_to_area
from modalviewer.core.mesh import Mesh, MeshError, remove_unused
from modalviewer.core.primitives import icosphere


def padded(mesh: Mesh):
    """The mesh's arrays with unused vertices at the start (0, 1), in the middle and at
    the end, and a duplicate of vertex 3 (appended) that two faces use: (vertices,
    faces, input index of each mesh vertex, the duplicate, the unused vertices)."""
    n = mesh.n_vertices
    far = np.array([[50.0, 50.0, 50.0]])
    half = n // 2
    v = np.vstack([far, far + 1, mesh.vertices[:half], far + 2, mesh.vertices[half:], far + 3])
    where = np.concatenate([np.arange(half) + 2, np.arange(half, n) + 3])
    v = np.vstack([v, mesh.vertices[[3]]])
    f = where[mesh.faces]
    dup = len(v) - 1
    two = np.flatnonzero((mesh.faces == 3).any(axis=1))[:2]
    f[two] = np.where(f[two] == where[3], dup, f[two])
    unused = np.array([0, 1, half + 2, len(v) - 2])
    return v, f, where, dup, unused


@pytest.fixture(scope="module")
def base():
    return icosphere(2)


@pytest.fixture(scope="module")
def case(base):
    v, f, where, dup, unused = padded(base)
    return v, f, where, dup, unused, repair_mesh(v, f, source="padded")


def test_identity_when_every_vertex_is_used(base):
    assert base.solver_mesh is base and base.unused.size == 0
    assert np.array_equal(base.merged_into, np.arange(base.n_vertices))
    assert repair_mesh(base.vertices, base.faces).solver_mesh.hash == base.hash


def test_the_mesh_keeps_every_input_vertex_in_its_place(base, case):
    v, f, where, dup, unused, m = case
    assert m.n_vertices == len(v)
    np.testing.assert_array_equal(m.vertices, v)
    np.testing.assert_array_equal(m.unused, unused)
    assert m.merged_into[dup] == where[3]
    assert not np.isin(dup, m.faces)  # the faces use the vertex it was merged into
    # the solver's mesh is the clean mesh, bit for bit
    assert m.solver_mesh.hash == base.hash
    assert m.component_labels[dup] == m.component_labels[where[3]] == 0
    assert np.all(m.component_labels[unused] == -1) and m.n_components == 1
    text = str(m.report)
    assert f"vertex {dup} into {where[3]}, counting from 0" in text
    assert f"vertices 0, 1, {unused[2]}, {unused[3]}, counting from 0" in text
    assert text.startswith("padded: 167 vertices (4 used by no face)")


def test_an_unused_vertex_is_a_clear_error_as_a_source(case):
    *_, unused, m = case
    with pytest.raises(MeshError, match=r"vertex 1 \(counting from 0\) is used by no face"):
        m.mesh_vertex(1)
    spec = mv.compute_spectrum(m, "laplacian", k=8)
    for bad in unused:
        with pytest.raises(ValueError, match=f"vertex {bad} .*used by no face"):
            mv.multiscale_distance(spec, int(bad))
        with pytest.raises(ValueError, match=f"vertex {bad} .*used by no face"):
            mv.cross_distance(spec, int(bad), spec)


@pytest.mark.parametrize("operator", ["laplacian", "shells"])
def test_results_have_one_row_per_input_vertex(base, case, operator):
    v, f, where, dup, unused, m = case
    clean = mv.compute_spectrum(base, operator, k=20)
    spec = mv.compute_spectrum(m, operator, k=20)
    assert spec.n_vertices == len(v) and spec.mesh_hash == m.hash
    np.testing.assert_allclose(spec.eigenvalues, clean.eigenvalues, rtol=1e-12, atol=1e-12)
    # the same solve: the rows of the input's vertices are the clean mesh's rows
    np.testing.assert_allclose(spec.modes[where], clean.modes, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(spec.modes[dup], spec.modes[where[3]])
    assert np.all(np.isnan(spec.modes[unused]))
    assert np.all(spec.mass[unused] == 0) and spec.mass[dup] == 0
    np.testing.assert_allclose(spec.mass[where], clean.mass, rtol=1e-15)
    # signatures and distances in the same rows
    _, sig = mv.signature(spec)
    _, sig_clean = mv.signature(clean)
    assert sig.shape[0] == len(v) and np.all(np.isnan(sig[unused]))
    np.testing.assert_allclose(sig[where], sig_clean, rtol=1e-10)
    d = mv.multiscale_distance(spec, where[7])
    np.testing.assert_allclose(d[where], mv.multiscale_distance(clean, 7), rtol=1e-10, atol=1e-14)
    assert d[where[7]] == 0.0 and np.all(np.isnan(d[unused]))
    np.testing.assert_allclose(
        mv.multiscale_distance(spec, dup), mv.multiscale_distance(spec, where[3]), equal_nan=True
    )
    # between shapes: the input's numbers in and out
    w, dist = mv.best_match(spec, where[7], spec)
    assert w == where[7] and dist == pytest.approx(0.0, abs=1e-12)
    cross = mv.cross_distance(spec, where[7], spec)
    np.testing.assert_allclose(cross, d, rtol=1e-8, atol=1e-12, equal_nan=True)
    euclid = spec.euclidean_modes()
    assert np.all(np.isfinite(euclid[where]))


def test_matrices_have_empty_rows_at_unused_vertices(base, case):
    v, f, where, dup, unused, m = case
    K, M = mv.operator_matrices(m, "laplacian")
    Kc, Mc = mv.operator_matrices(base, "laplacian")
    assert K.shape == (len(v), len(v))
    for i in (*unused, dup):
        assert K[[i]].nnz == 0 and M.diagonal()[i] == 0
    np.testing.assert_allclose(K[where][:, where].toarray(), Kc.toarray(), atol=1e-13)
    np.testing.assert_allclose(M.diagonal()[where], Mc.diagonal(), rtol=1e-15)


def test_a_saved_spectrum_keeps_its_rows(case, tmp_path):
    *_, unused, m = case
    spec = mv.compute_spectrum(m, "laplacian", k=6)
    mv.save_spectrum(spec, tmp_path / "s.npz")
    back = mv.load_spectrum(tmp_path / "s.npz", mesh=m)
    np.testing.assert_array_equal(back.modes, spec.modes)


def test_remove_unused_gives_the_compact_mesh_and_its_map(base, case):
    v, f, where, dup, unused, m = case
    compact, kept = remove_unused(m)
    np.testing.assert_array_equal(kept, where)
    assert compact.hash == base.hash and compact.unused.size == 0
    np.testing.assert_array_equal(compact.vertices, v[kept])


def test_derived_meshes_keep_the_numbering(base, case):
    v, f, where, dup, unused, m = case
    scaled = rescale_to_area(m, 1.0)
    np.testing.assert_array_equal(scaled.merged_into, m.merged_into)
    np.testing.assert_array_equal(scaled.unused, m.unused)
    small = icosphere(0)
    v2 = np.vstack([v, small.vertices * 0.1 + 10])
    f2 = np.vstack([f, small.faces + len(v)])
    two = repair_mesh(v2, f2)
    big = largest_component(two)
    assert big.n_vertices == len(v2)
    np.testing.assert_array_equal(big.unused, np.concatenate([unused, np.arange(len(v), len(v2))]))
    assert big.merged_into[dup] == where[3]
    assert "Kept the largest of 2 connected components (162 vertices" in str(big.report)
    (first, first_vertices), (part, vertices) = split_components(two)
    np.testing.assert_array_equal(first_vertices, where)
    np.testing.assert_array_equal(vertices, np.arange(len(v), len(v2)))
    np.testing.assert_array_equal(part.vertices, v2[vertices])


def test_an_unused_vertex_at_a_used_ones_place_is_not_merged_with_it(base):
    v = np.vstack([base.vertices[[4]], base.vertices])
    m = repair_mesh(v, base.faces + 1)
    np.testing.assert_array_equal(m.unused, [0])
    assert m.mesh_vertex(5) == 5
    assert "Merged" not in str(m.report)


def test_without_repair_an_unused_vertex_is_named_not_a_degenerate_face(base):
    v = np.vstack([base.vertices, [[7.0, 7.0, 7.0]]])
    m = mv.as_mesh((v, base.faces), repair=False)
    np.testing.assert_array_equal(m.unused, [base.n_vertices])
    spec = mv.compute_spectrum(m, "laplacian", k=5)
    assert np.all(np.isnan(spec.modes[-1])) and np.all(np.isfinite(spec.modes[:-1]))


def test_modes_handed_over_as_they_converge_are_in_the_input_numbering(case):
    v, f, where, dup, unused, m = case
    calls = []
    final = mv.compute_spectrum(m, "laplacian", k=8, on_modes=calls.append)
    assert calls and all(s.n_vertices == len(v) for s in calls)
    assert all(np.all(np.isnan(s.modes[unused])) for s in calls)
    np.testing.assert_array_equal(calls[-1].modes[where], final.modes[where])


def test_the_local_signature_takes_input_vertices(base, case):
    v, f, where, dup, unused, m = case
    times = np.array([0.05, 0.5])
    got = mv.local_signature(m, "laplacian", [where[5], dup], times)
    want = mv.local_signature(base, "laplacian", [5, 3], times)
    np.testing.assert_allclose(got, want, rtol=1e-10)
    spec = mv.compute_spectrum(m, "laplacian", k=10)
    with_spec = mv.local_signature(m, "laplacian", [where[5]], times, spectrum=spec)
    np.testing.assert_allclose(with_spec, want[:1], rtol=1e-8)
    with pytest.raises(MeshError, match=f"vertex {unused[1]} .*used by no face"):
        mv.local_signature(m, "laplacian", [unused[1]], times)


@pytest.mark.parametrize("operator", ["laplacian", "laplacian_robust", "shells"])
def test_every_operators_matrices_are_empty_at_unused_vertices(base, case, operator):
    if operator == "laplacian_robust":
        pytest.importorskip("robust_laplacian")
    v, f, where, dup, unused, m = case
    K, M = mv.operator_matrices(m, operator)
    Kc, Mc = mv.operator_matrices(base, operator)
    per = K.shape[0] // len(v)
    rows = (per * where[:, None] + np.arange(per)).ravel()
    empty = (per * np.r_[unused, dup][:, None] + np.arange(per)).ravel()
    assert abs(K[empty]).sum() == 0 and np.all(M.diagonal()[empty] == 0)
    np.testing.assert_allclose(K[rows][:, rows].toarray(), Kc.toarray(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(M.diagonal()[rows], Mc.diagonal(), rtol=1e-15)
