"""Issue 25: vertex numbers are the file's, although the Mesh is compact."""

import numpy as np
import pytest

from modalviewer.core.components import largest_component, split_components
from modalviewer.core.cross import rescale_to_area
from modalviewer.core.mesh import Mesh, MeshError, repair_mesh
from modalviewer.core.primitives import icosphere


def padded(mesh: Mesh):
    """The mesh's arrays with unused vertices before, between and after the used ones
    and a duplicate of vertex 3: (vertices, faces, file index of each mesh vertex)."""
    n = mesh.n_vertices
    far = np.array([[50.0, 50.0, 50.0]])
    half = n // 2
    v = np.vstack([far, far + 1, mesh.vertices[:half], far + 2, mesh.vertices[half:], far + 3])
    where = np.concatenate([np.arange(half) + 2, np.arange(half, n) + 3])
    v = np.vstack([v, mesh.vertices[[3]]])  # a duplicate of mesh vertex 3 at the end
    f = where[mesh.faces]
    dup = len(v) - 1
    two = np.flatnonzero((mesh.faces == 3).any(axis=1))[:2]  # two faces use the copy
    f[two] = np.where(f[two] == where[3], dup, f[two])
    return v, f, where, dup


def test_identity_when_nothing_dropped():
    m = icosphere(1)
    assert not m.renumbered and m.file_map is None
    assert m.n_file_vertices == m.n_vertices
    assert np.array_equal(m.file_vertices, np.arange(m.n_vertices))
    assert m.mesh_vertex(5) == 5 and m.file_vertex(5) == 5
    assert not repair_mesh(m.vertices, m.faces).renumbered


def test_maps_of_a_file_with_unused_and_duplicate_vertices():
    base = icosphere(1)
    v, f, where, dup = padded(base)
    m = repair_mesh(v, f)
    assert m.n_vertices == base.n_vertices and m.n_file_vertices == len(v)
    assert np.allclose(m.vertices, base.vertices)
    assert np.array_equal(m.file_vertices, where)
    assert np.array_equal(m.file_to_mesh[where], np.arange(base.n_vertices))
    unused = [0, 1, where[base.n_vertices // 2 - 1] + 1, len(v) - 2]
    assert np.all(m.file_to_mesh[unused] == -1)
    assert m.mesh_vertex(dup) == 3 and m.file_vertex(3) == where[3]
    with pytest.raises(MeshError, match="vertex 1 of the file is used by no face"):
        m.mesh_vertex(1)
    with pytest.raises(MeshError, match="not in the file"):
        m.mesh_vertex(len(v))
    field = m.to_file_field(np.arange(m.n_vertices))
    assert field.shape == (len(v),)
    assert np.all(np.isnan(field[unused]))
    assert field[dup] == field[where[3]] == 3
    assert np.array_equal(field[where], np.arange(m.n_vertices))
    text = str(m.report)
    assert f"vertex {dup} into {where[3]}" in text
    assert f"vertices 0, 1, {unused[2]}, {unused[3]}" in text


def test_an_unused_vertex_at_a_used_ones_place_is_not_merged_with_it():
    # an unused vertex 0 where vertex 5 of the file (used) lies: vertex 5 keeps its
    # number (it was shown as vertex 0, a vertex no face uses, "merged" into it)
    base = icosphere(1)
    v = np.vstack([base.vertices[[4]], base.vertices])
    m = repair_mesh(v, base.faces + 1)
    assert m.n_vertices == base.n_vertices
    assert m.file_vertex(m.mesh_vertex(5)) == 5 and m.file_vertex(4) == 5
    with pytest.raises(MeshError, match="vertex 0 of the file is used by no face"):
        m.mesh_vertex(0)
    text = str(m.report)
    assert "Merged" not in text and "(no face uses it; the file's vertex 0;" in text


def test_derived_meshes_keep_the_map():
    base = icosphere(1)
    v, f, where, dup = padded(base)
    m = repair_mesh(v, f)
    scaled = rescale_to_area(m, 1.0)
    assert np.array_equal(scaled.file_to_mesh, m.file_to_mesh)
    # two spheres: the largest component keeps file numbers, the other's become unused
    small = icosphere(0)
    v2 = np.vstack([v, small.vertices * 0.1 + 10])
    f2 = np.vstack([f, small.faces + len(v)])
    two = repair_mesh(v2, f2)
    big = largest_component(two)
    assert big.n_file_vertices == len(v2)
    assert np.array_equal(big.file_vertices, where)
    assert np.all(big.file_to_mesh[len(v) :] == -1)
    (_, _), (part, _) = split_components(two)
    assert np.array_equal(part.file_vertices, np.arange(len(v), len(v2)))


def test_fix_slivers_keeps_the_map_when_nothing_changes_and_says_when_it_renumbers():
    from modalviewer.core.primitives import add_slivers
    from modalviewer.repair import fix_slivers

    base = icosphere(1)
    v, f, where, dup = padded(base)
    m = repair_mesh(v, f)
    same = fix_slivers(m)
    assert np.array_equal(same.file_to_mesh, m.file_to_mesh)
    pytest.importorskip("pymeshlab")
    sv, sf = add_slivers(icosphere(2), needles=5, caps=5, eps=1e-8, seed=2)
    sm = repair_mesh(np.vstack([[[9.0, 9.0, 9.0]], sv]), sf + 1)
    assert sm.renumbered
    fixed = fix_slivers(sm)
    assert not fixed.renumbered and fixed.n_file_vertices == fixed.n_vertices
    assert "numbers the vertices anew" in str(fixed.report)
