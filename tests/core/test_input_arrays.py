"""Vertex and face arrays are checked before anything is done with them: never
reshaped, quads split with the report saying so, fractional indices refused."""

import numpy as np
import pytest

import modalviewer as mv
from scripts.make_assets import plate


@pytest.fixture(scope="module")
def arrays():
    m = plate()
    return np.array(m.vertices), np.array(m.faces)


def _quads(nx=6, ny=5):
    x, y = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), indexing="ij")
    v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    idx = np.arange(v.shape[0]).reshape(nx + 1, ny + 1)
    q = np.column_stack(
        [idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()]
    )
    return v, q


@pytest.mark.parametrize("make", [mv.as_mesh, lambda a: mv.Mesh(*a), lambda a: mv.repair_mesh(*a)])
def test_transposed_faces_are_refused_with_the_transpose_suggested(arrays, make):
    v, f = arrays
    with pytest.raises(mv.MeshError, match=r"faces\.T"):
        make((v, f.T))


def test_transposed_vertices_are_refused(arrays):
    v, f = arrays
    with pytest.raises(mv.MeshError, match=r"vertices\.T"):
        mv.as_mesh((v.T, f))


def test_quads_are_split_and_the_report_says_so():
    v, q = _quads()  # 30 quads: a multiple of 3, which a reshape would have taken
    assert len(q) % 3 == 0
    mesh = mv.as_mesh((v, q))
    assert mesh.n_faces == 2 * len(q)
    assert "Split 30 quads into 60 triangles" in str(mesh.report)
    # the area of the 6 x 5 grid, to rounding
    assert mesh.face_areas.sum() == pytest.approx(30.0, rel=1e-12)


def test_a_mesh_object_refuses_quads():
    v, q = _quads()
    with pytest.raises(mv.MeshError, match="polygons of 4 vertices"):
        mv.Mesh(v, q)


def test_quads_of_another_count_give_no_reshape_error():
    v, q = _quads(4, 4)  # 16 quads: 64 indices, not a multiple of 3
    mesh = mv.as_mesh((v, q))
    assert mesh.n_faces == 32


@pytest.mark.parametrize("repair", [True, False])
def test_fractional_face_indices_are_refused(arrays, repair):
    v, f = arrays
    with pytest.raises(mv.MeshError, match="whole numbers"):
        mv.as_mesh((v, f + 0.7), repair=repair)


@pytest.mark.parametrize("repair", [True, False])
def test_whole_float_face_indices_are_taken(arrays, repair):
    v, f = arrays
    mesh = mv.as_mesh((v, f.astype(np.float64)), repair=repair)
    assert np.array_equal(mesh.faces, f)


@pytest.mark.parametrize("repair", [True, False])
def test_out_of_range_indices_and_nan_vertices_are_refused(arrays, repair):
    v, f = arrays
    bad = f.copy()
    bad[3, 1] = len(v)
    with pytest.raises(mv.MeshError, match="does not exist"):
        mv.as_mesh((v, bad), repair=repair)
    w = v.copy()
    w[5, 2] = np.nan
    with pytest.raises(mv.MeshError, match="NaN or infinite"):
        mv.as_mesh((w, f), repair=repair)


def test_boolean_faces_are_refused(arrays):
    v, f = arrays
    with pytest.raises(mv.MeshError, match="integers"):
        mv.as_mesh((v, f > 3))
