"""Degenerate and sliver triangles: the loader collapses zero-area faces instead of
punching holes, fix_slivers removes needles and caps by flips and collapses, and a
spectrum that fails on slivers says so."""

import numpy as np
import pytest

import modalviewer as mv
from benchmarks.slivers import add_slivers
from modalviewer.core.mesh import triangle_quality
from modalviewer.core.primitives import grid_plate, icosphere


def boundary_length(mesh):
    e = mesh.edges[mesh.edge_face_counts == 1]
    return float(np.linalg.norm(mesh.vertices[e[:, 0]] - mesh.vertices[e[:, 1]], axis=1).sum())


def euler(mesh):
    mesh = mesh.solver_mesh  # the vertices faces use
    return mesh.n_vertices - len(mesh.edges) + mesh.n_faces


# ----------------------------------------------------------------- quality
def test_triangle_quality_values():
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 3**0.5 / 2, 0], [0.5, 1e-3, 0], [0, 1, 0]])
    q = triangle_quality(v, np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]))
    # equilateral 1; a cap of height h over L = 1: 4 sqrt(3) (h / 2) / (1 + 2 (1/4 + h^2));
    # the right isosceles triangle 2 sqrt(3) / 4
    cap = 2 * 3**0.5 * 1e-3 / (1.5 + 2e-6)
    np.testing.assert_allclose(q, [1.0, cap, 3**0.5 / 2], rtol=1e-12)
    assert icosphere(2).face_quality.min() > 0.8


# ------------------------------------------------------------- the loader
def _write_obj(path, v, f):
    path.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in v)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f)
    )
    return path


def _zero_area_count(v, f):
    double = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return int((0.5 * double < 1e-15).sum())


def test_loader_flips_zero_area_caps_and_a_closed_mesh_stays_closed(tmp_path):
    # a vertex in the middle of an edge (a T-junction): the edge is flipped, nothing moves
    sphere = icosphere(2)
    v, f = add_slivers(sphere, needles=0, caps=10, eps=0.0)
    assert _zero_area_count(v, f) == 10
    mesh = mv.load_mesh(_write_obj(tmp_path / "caps.obj", v, f))
    text = str(mesh.report)
    assert mesh.n_boundary_edges == 0  # 30 boundary edges when deleted
    assert euler(mesh) == 2 and mesh.n_components == 1 and mesh.is_consistently_oriented
    assert "Flipped the longest edge of 10 degenerate (zero-area) faces" in text
    assert "no vertex moved" in text
    np.testing.assert_array_equal(mesh.vertices, v)  # every vertex kept, none moved
    assert mesh.n_faces == len(f)
    assert mesh.total_area == pytest.approx(sphere.total_area, rel=1e-14)
    assert mesh.face_quality.min() > 0.3


def test_loader_collapses_zero_area_caps_near_a_corner(tmp_path):
    # a vertex on an edge next to its end: the short edge is collapsed
    sphere = icosphere(2)
    v, f = add_slivers(sphere, needles=0, caps=10, eps=0.0, at=0.02)
    mesh = mv.load_mesh(_write_obj(tmp_path / "caps.obj", v, f))
    text = str(mesh.report)
    assert mesh.n_boundary_edges == 0 and euler(mesh) == 2 and mesh.is_consistently_oriented
    assert "Collapsed 10 degenerate (zero-area) faces" in text and "no holes" in text
    # each cap's apex was only used by the split face: the sphere comes back exactly
    # (the apexes keep their numbers, merged into the vertex they were collapsed onto)
    assert mesh.n_vertices == len(v) and np.sum(mesh.merged_into != np.arange(len(v))) == 10
    solved = mesh.solver_mesh
    assert solved.n_vertices == sphere.n_vertices and solved.n_faces == sphere.n_faces
    np.testing.assert_array_equal(solved.vertices, sphere.vertices)
    same = {tuple(np.roll(t, -np.argmin(t))) for t in sphere.faces}
    assert {tuple(np.roll(t, -np.argmin(t))) for t in solved.faces} == same


def test_loader_keeps_the_boundary_of_an_open_mesh():
    plate = grid_plate(6, 6)
    v, f = add_slivers(plate, needles=0, caps=12, eps=0.0, seed=3)
    mesh = mv.repair_mesh(v, f, source="plate")
    text = str(mesh.report)
    assert "Flipped" in text and "lying along the boundary" in text
    # the outline is still the unit square: no interior holes, no lost area
    assert boundary_length(mesh) == pytest.approx(4.0, rel=1e-12)
    assert mesh.total_area == pytest.approx(1.0, rel=1e-12)
    assert euler(mesh) == 1 and mesh.n_components == 1 and mesh.is_edge_manifold


def test_loader_collapse_never_glues_sheets():
    # two parallel plates a hair apart would be glued by a careless collapse; a zero-area
    # face lying on top of a plate's boundary is removed instead (the boundary line is the
    # same): the plate stays whole
    plate = grid_plate(4, 4)
    extra = np.array([[0, 1, 2]])  # collinear: the first row of the plate
    mesh = mv.repair_mesh(plate.vertices, np.vstack([plate.faces, extra]))
    assert mesh.n_faces == plate.n_faces
    np.testing.assert_array_equal(mesh.vertices, plate.vertices)
    assert "lying along the boundary" in str(mesh.report)


# -------------------------------------------------------------- fix_slivers
@pytest.fixture(scope="module")
def slivered_sphere():
    sphere = icosphere(3)
    v, f = add_slivers(sphere, needles=20, caps=20, eps=1e-8, seed=2)
    return sphere, mv.Mesh(v, f)


def test_fix_slivers_removes_needles_and_caps_and_keeps_the_surface(slivered_sphere):
    sphere, bad = slivered_sphere
    assert bad.n_boundary_edges == 0 and (bad.face_quality < 1e-3).sum() == 60
    stages = []
    fixed = mv.fix_slivers(bad, progress=lambda stage, x: stages.append((stage, x)))
    assert stages[0][1] == 0.0 and stages[-1] == ("done", 1.0)
    assert all(a[1] <= b[1] for a, b in zip(stages, stages[1:], strict=False))
    r = fixed.report
    assert isinstance(r, mv.SliverReport)
    # topology: still one closed sphere
    assert fixed.n_boundary_edges == 0 and euler(fixed) == 2 and fixed.n_components == 1
    assert fixed.is_edge_manifold and fixed.is_consistently_oriented
    # quality: from 1e-8 to a healthy mesh (the icosphere's own worst is 0.86)
    assert bad.face_quality.min() < 2e-8
    assert fixed.face_quality.min() > 0.05
    assert r.worst_quality_before == pytest.approx(bad.face_quality.min(), rel=1e-12)
    assert r.worst_quality_after == pytest.approx(fixed.face_quality.min(), rel=1e-12)
    assert (r.slivers_before, r.slivers_after) == (60, 0)
    assert (r.below_min_quality_before, r.below_min_quality_after) == (60, 0)
    # the changes stay near the slivers and move nothing visibly
    assert 60 <= r.triangles_changed <= 300
    assert r.triangles_before == bad.n_faces and r.triangles_after == fixed.n_faces
    assert r.vertices_removed == bad.n_vertices - fixed.n_vertices >= 20  # the needles
    assert r.max_vertex_shift < 1e-7 and r.max_deviation < 1e-7
    assert fixed.total_area == pytest.approx(bad.total_area, rel=1e-7)
    assert "Changed" in str(r) and "worst quality" in str(r)
    # unchanged vertices are bit for bit the input's
    before = {tuple(p) for p in bad.vertices}
    kept = sum(tuple(p) in before for p in fixed.vertices)
    assert kept >= fixed.n_vertices - 20  # at most one moved per needle


def test_shells_fail_on_slivers_and_compute_after_fix_slivers(slivered_sphere):
    sphere, bad = slivered_sphere
    with pytest.raises(mv.EigenError) as info:
        mv.compute_spectrum(bad, "shells", k=10)
    message = str(info.value)
    assert "fix_slivers" in message and "Mesh > Fix slivers" in message
    fixed = mv.fix_slivers(bad)
    spec = mv.compute_spectrum(fixed, "shells", k=16)
    assert np.all(np.abs(spec.eigenvalues[:6]) < 1e-8 * spec.eigenvalues[6])  # rigid motions
    assert spec.residuals[6:].max() < 1e-8
    clean = mv.compute_spectrum(sphere, "shells", k=16)
    # the repaired mesh is a slightly different triangulation of the same sphere
    np.testing.assert_allclose(spec.eigenvalues[6:], clean.eigenvalues[6:], rtol=0.03)


def test_fix_slivers_on_an_open_mesh_keeps_its_boundary():
    plate = grid_plate(12, 12)
    v, f = add_slivers(plate, needles=10, caps=10, eps=1e-8, seed=1)
    bad = mv.Mesh(v, f)
    fixed = mv.fix_slivers(bad)
    assert fixed.n_boundary_edges == bad.n_boundary_edges
    assert boundary_length(fixed) == pytest.approx(4.0, rel=1e-7)
    assert fixed.total_area == pytest.approx(1.0, rel=1e-7)
    assert fixed.face_quality.min() > 0.05 and bad.face_quality.min() < 1e-7


def test_fix_slivers_leaves_a_good_mesh_alone():
    sphere = icosphere(2)
    fixed = mv.fix_slivers(sphere)
    np.testing.assert_array_equal(fixed.vertices, sphere.vertices)
    np.testing.assert_array_equal(fixed.faces, sphere.faces)
    assert fixed.report.triangles_changed == 0 and "nothing was changed" in str(fixed.report)
    with pytest.raises(ValueError, match="min_quality"):
        mv.fix_slivers(sphere, min_quality=1.5)


def test_fix_slivers_falls_back_to_local_remeshing(slivered_sphere, monkeypatch):
    # MeshLab's T-vertex collapses do not check the link condition; where they would
    # change the topology (on a 143k-vertex iso-surface with 11k slivers they made edges
    # non-manifold), the slivers' neighbourhood is remeshed instead
    from modalviewer.repair import slivers as repair

    sphere, bad = slivered_sphere
    monkeypatch.setattr(repair, "_METHODS", {"remesh": repair._METHODS["remesh"]})
    fixed = mv.fix_slivers(bad)
    r = fixed.report
    assert "remeshing" in r.method and "remeshing" in str(r)
    assert fixed.n_boundary_edges == 0 and euler(fixed) == 2 and fixed.is_consistently_oriented
    assert r.slivers_after == 0 and r.worst_quality_after > 0.03
    # the rest of the sphere is untouched, and the new vertices lie on the old surface
    assert r.triangles_changed < bad.n_faces / 2
    assert r.max_vertex_shift < 1e-6 and r.max_deviation < 0.01
    assert fixed.total_area == pytest.approx(bad.total_area, rel=0.01)


def test_fix_slivers_without_pymeshlab_says_what_to_install(slivered_sphere, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "pymeshlab", None)  # import pymeshlab -> ImportError
    with pytest.raises(mv.MeshError, match="pip install pymeshlab"):
        mv.fix_slivers(slivered_sphere[1])
