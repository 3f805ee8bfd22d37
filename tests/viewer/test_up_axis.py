"""The up axis: detected +Z where a mesh clearly stands on the XY plane, chosen through
the state, used by the canonical view (R) and by Viewer.set_view."""

from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.mesh import Mesh
from modalviewer.viewer import Viewer
from modalviewer.viewer.camera import canonical_view, detect_up, parse_view, up_axis_of

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def _z_up(vertices):
    """A Y-up model turned to Z-up (a quarter turn about X): y -> z, z -> -y."""
    v = np.asarray(vertices)
    return np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])


def _box(lo, hi):
    """A closed box (8 vertices, 12 triangles, outward normals)."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = np.array(
        [[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)], dtype=np.float64
    )
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return v, np.array(f)


def _table_y_up():
    """A table standing on the XZ plane, +Y up: a top and four legs."""
    parts = [_box((-1.0, 0.9, -0.6), (1.0, 1.0, 0.6))]
    for x in (-0.9, 0.8):
        for z in (-0.5, 0.4):
            parts.append(_box((x, 0.0, z), (x + 0.1, 0.9, z + 0.1)))
    vertices, faces, offset = [], [], 0
    for v, f in parts:
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.vstack(vertices), np.vstack(faces)


def test_a_z_up_cow_and_table_are_detected_and_their_y_up_originals_not():
    cow = mv.load_mesh(ASSETS / "spot.obj")
    assert detect_up(cow.vertices, cow.faces) is None
    assert detect_up(_z_up(cow.vertices), cow.faces) == "+z"
    v, f = _table_y_up()
    assert detect_up(v, f) is None
    assert detect_up(_z_up(v), f) == "+z"
    assert up_axis_of(_z_up(v), f) == "+z"
    assert up_axis_of(_z_up(v), f, chosen="-x") == "-x"
    # a column on a wide slab (a statue on its base), closed: the flat base claims +Z
    slab, column = _box((-1, -1, 0), (1, 1, 0.2)), _box((-0.2, -0.2, 0.2), (0.2, 0.2, 2))
    v = np.vstack([slab[0], column[0]])
    f = np.vstack([slab[1], column[1] + 8])
    assert detect_up(v, f) == "+z"
    assert detect_up(_z_up(_z_up(_z_up(v))), f) is None  # the same statue, +Y up


def _figure_y_up():
    """A figure standing on two feet, +Y up: two legs under a body, the legs' backs
    (the bottom slice along z) behind the body's, and two hands and a nose sticking out
    in front (+z), as a scanned person's front touches a slice in several places."""
    parts = [
        _box((-0.2, 0.0, -0.05), (-0.05, 1.0, 0.35)),
        _box((0.05, 0.0, -0.05), (0.2, 1.0, 0.35)),
        _box((-0.3, 1.0, 0.0), (0.3, 2.2, 0.3)),
        _box((-0.28, 1.3, 0.3), (-0.2, 1.4, 0.5)),
        _box((0.2, 1.3, 0.3), (0.28, 1.4, 0.5)),
        _box((-0.03, 2.0, 0.3), (0.03, 2.05, 0.5)),
    ]
    faces = [f + 8 * i for i, (_, f) in enumerate(parts)]
    return np.vstack([v for v, _ in parts]), np.vstack(faces)


def test_a_figure_on_two_feet_is_detected_z_up_and_its_y_up_original_not():
    v, f = _figure_y_up()
    assert detect_up(v, f) is None
    assert detect_up(_z_up(v), f) == "+z"


@pytest.mark.parametrize("name", ["demo_folded_plate", "demo_machined_part", "demo_hand"])
def test_the_demo_meshes_keep_y_up(name):
    mesh = mv.load_mesh(ASSETS / f"{name}.obj")
    assert detect_up(mesh.vertices, mesh.faces) is None


def test_the_canonical_view_of_a_z_up_cow_stands_it_upright():
    cow = mv.load_mesh(ASSETS / "spot.obj")
    z_up = Mesh(_z_up(cow.vertices), cow.faces)
    viewer = Viewer()
    viewer.set_mesh(z_up)
    assert viewer.state.derived.up_axis() == "+z"
    viewer.renderer((200, 150))
    up = np.asarray(viewer.current_camera()["view_up"])
    assert up[2] > 0.9  # +Z at the top of the screen (the +Y default would lay it down)
    # choosing +Y turns to the canonical view for +Y, and R (reset) keeps it
    viewer.state.up_axis = "+y"
    assert np.asarray(viewer.current_camera()["view_up"])[1] > 0.9
    viewer.renderer().drawing.reset_camera()
    assert np.asarray(viewer.current_camera()["view_up"])[1] > 0.9
    viewer.state.up_axis = "auto"
    assert viewer.state.up_axis is None
    assert np.asarray(viewer.current_camera()["view_up"])[2] > 0.9
    with pytest.raises(ValueError, match="up axis"):
        viewer.state.up_axis = "up"
    viewer.close()


def test_set_view_turns_the_camera_to_presets_and_angles():
    mesh = mv.load_mesh(ASSETS / "demo_machined_part.obj")
    viewer = Viewer()
    viewer.set_mesh(mesh)
    viewer.renderer((160, 120))
    cam = viewer.set_view("+x")
    direction = np.subtract(cam["position"], cam["focal_point"])
    assert np.allclose(direction / np.linalg.norm(direction), [1, 0, 0])
    assert np.allclose(np.subtract(viewer.current_camera()["position"], cam["focal_point"])[1:], 0)
    # azimuth 90 about +Y from the front (+Z) looks from +X; elevation 90 from above
    for view, expected in (("90,0", [1, 0, 0]), ("0,0", [0, 0, 1]), ((0, 90), [0, 1, 0])):
        cam = viewer.set_view(view)
        d = np.subtract(cam["position"], cam["focal_point"])
        assert np.allclose(d / np.linalg.norm(d), expected, atol=1e-9), view
    cam = viewer.set_view("0,0", up="+z")  # front of +Z up: +X
    d = np.subtract(cam["position"], cam["focal_point"])
    assert np.allclose(d / np.linalg.norm(d), [1, 0, 0], atol=1e-9)
    assert np.allclose(cam["view_up"], [0, 0, 1], atol=1e-9)
    viewer.close()


def test_views_parse_and_bad_ones_are_refused():
    assert parse_view("iso") == "isometric"
    assert parse_view("+Z") == "+z"
    assert parse_view("30,-10") == (30.0, -10.0)
    for bad in ("top", "30", "30,100", "a,b", "nan,0"):
        with pytest.raises(ValueError, match="unknown view"):
            parse_view(bad)


def test_the_canonical_view_uses_the_up_axis_given():
    cow = mv.load_mesh(ASSETS / "spot.obj")
    cam = canonical_view(_z_up(cow.vertices), cow.faces, up="+z")
    assert cam.up[2] > 0.9


@pytest.mark.parametrize("name", ["spot.obj", "demo_hand.obj"])
def test_a_model_turned_to_z_up_is_seen_from_the_same_side(name):
    """Turning a Y-up model a quarter about X (y -> z, z -> -y: its front, +Z, goes to -Y,
    where Z-up tools put the front) turns its canonical view with it: the Z-up copy is
    seen from its front, not from behind."""
    mesh = mv.load_mesh(ASSETS / name)
    y_up = canonical_view(mesh.vertices, mesh.faces, up="+y")
    z_up = canonical_view(_z_up(mesh.vertices), mesh.faces, up="+z")
    turned = _z_up(np.array([y_up.direction, y_up.up]))
    np.testing.assert_allclose(z_up.direction, turned[0], atol=1e-6)
    np.testing.assert_allclose(z_up.up, turned[1], atol=1e-6)
