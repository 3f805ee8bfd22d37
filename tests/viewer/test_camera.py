"""The canonical first view and the camera presets (modalviewer.viewer.camera, no Qt)."""

import numpy as np
import pytest

from modalviewer.core.primitives import grid_plate
from modalviewer.viewer.camera import (
    Camera,
    canonical_camera,
    canonical_view,
    preset_view,
    principal_axes,
)


def _box_points(size, n=2000, seed=0):
    """Points on the surface of an axis-aligned box of the given size, centred at 0."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-0.5, 0.5, (n, 3))
    axis = rng.integers(0, 3, n)
    p[np.arange(n), axis] = np.sign(p[np.arange(n), axis]) * 0.5
    return p * np.asarray(size)


def _rotation(seed=3):
    q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_straight_view_looks_at_the_largest_silhouette():
    # long in X, tall in Y, thin in Z: the largest silhouette is seen along Z
    v = _box_points((4.0, 2.0, 0.5)) + [10.0, -3.0, 1.0]
    cam = canonical_view(v, azimuth=0.0, elevation=0.0)
    assert np.allclose(cam.direction, [0, 0, 1], atol=1e-12)
    assert np.allclose(cam.up, [0, 1, 0], atol=1e-12)
    lo, hi = v.min(axis=0), v.max(axis=0)
    assert np.allclose(cam.focal_point, 0.5 * (lo + hi))
    # far enough to see the bounding sphere in VTK's 30-degree view angle
    dist = np.linalg.norm(np.subtract(cam.position, cam.focal_point))
    assert dist * np.sin(np.radians(15)) == pytest.approx(0.5 * np.linalg.norm(hi - lo))


def test_canonical_view_is_turned_a_little_and_keeps_up():
    v = _box_points((4.0, 2.0, 0.5))
    cam = canonical_view(v)  # azimuth 20, elevation 15
    d = cam.direction
    assert np.degrees(np.arccos(d @ [0, 0, 1])) == pytest.approx(np.hypot(20, 15), abs=2.5)
    assert d[1] > 0.2  # seen from a little above
    assert np.dot(cam.up, d) == pytest.approx(0.0, abs=1e-12)
    assert cam.up[1] > 0.95


def test_up_axis_from_the_caller_and_unsnapped_principal_axes():
    v = _box_points((4.0, 0.5, 2.0))  # thin in Y
    cam = canonical_view(v, up="z", azimuth=0.0, elevation=0.0)
    assert np.allclose(np.abs(cam.direction), [0, 1, 0], atol=1e-12)
    assert np.allclose(cam.up, [0, 0, 1], atol=1e-12)
    # a box turned far from the coordinate axes: the view follows its thin axis
    rot = _rotation()
    turned = _box_points((4.0, 2.0, 0.5)) @ rot.T
    _, axes = principal_axes(turned)
    thin = rot[:, 2]
    assert abs(axes[2] @ thin) > 0.999
    if np.max(np.abs(thin)) < np.cos(np.radians(25)):  # not snapped to an axis
        cam = canonical_view(turned, up=rot[:, 1], azimuth=0.0, elevation=0.0)
        assert abs(cam.direction @ thin) > 0.999


def test_a_plate_lying_across_the_up_axis_is_seen_from_above():
    plate = grid_plate(10, 10)  # in the XY plane
    v = plate.vertices[:, [0, 2, 1]]  # now in the XZ plane, +Y up
    cam = canonical_view(v, plate.faces, azimuth=0.0, elevation=0.0)
    assert np.allclose(cam.direction, [0, 1, 0], atol=1e-12)
    # the plate in its own plane faces the viewer with up the default +Y axis
    cam = canonical_view(plate.vertices, plate.faces, azimuth=0.0, elevation=0.0)
    assert np.allclose(np.abs(cam.direction), [0, 0, 1], atol=1e-12)


def _plate_part():
    """A machined plate 2 x 1 x 0.2 (flat side toward +Z), as a CAD export gives it:
    coplanar triangles on each face, sharp edges all round."""
    import trimesh

    box = trimesh.creation.box(extents=(2.0, 1.0, 0.2)).subdivide().subdivide()
    return np.asarray(box.vertices), np.asarray(box.faces)


def test_a_coarse_part_is_seen_along_its_largest_silhouette():
    # projected vertices of large triangles filled the same few cells from every side,
    # and the first view looked at the plate's narrow end
    v, f = _plate_part()
    cam = canonical_view(v, f, azimuth=0.0, elevation=0.0)
    assert np.allclose(cam.direction, [0, 0, 1], atol=1e-12)


def test_the_first_view_of_a_cad_like_part_shows_its_sides():
    v, f = _plate_part()
    d = canonical_view(v, f).direction
    # the flat front, the narrow side and the top each seen at 30 degrees or more from
    # grazing, so the sharp edges between them show (the default turn, 20 degrees of
    # azimuth and 15 of elevation, sees the side and the top nearly edge-on)
    assert np.all(np.abs(d) >= np.sin(np.radians(30.0))), d
    assert d[1] > 0  # from above


def test_a_smooth_mesh_keeps_the_default_turn():
    import modalviewer as mv

    spot = mv.load_mesh(mv.asset_path("spot.obj"))
    cam = canonical_view(spot.vertices, spot.faces)
    default = canonical_view(spot.vertices, spot.faces, azimuth=20.0, elevation=15.0)
    assert np.allclose(cam.direction, default.direction, atol=1e-12)


@pytest.mark.parametrize(
    "name, direction, up",
    [
        ("+x", (1, 0, 0), (0, 1, 0)),
        ("-x", (-1, 0, 0), (0, 1, 0)),
        ("+y", (0, 1, 0), (0, 0, -1)),
        ("-y", (0, -1, 0), (0, 0, 1)),
        ("+z", (0, 0, 1), (0, 1, 0)),
        ("-z", (0, 0, -1), (0, 1, 0)),
    ],
)
def test_axis_presets(name, direction, up):
    v = _box_points((1.0, 2.0, 3.0))
    cam = preset_view(v, name)
    assert np.allclose(cam.direction, direction, atol=1e-12)
    assert np.allclose(cam.up, up, atol=1e-12)


def test_isometric_preset_and_dict_form():
    plate = grid_plate(5, 5)
    cam = preset_view(plate.vertices, "isometric")
    assert np.allclose(cam.direction, np.ones(3) / np.sqrt(3))
    assert np.dot(cam.up, cam.direction) == pytest.approx(0.0, abs=1e-12)
    assert cam.up[1] > 0.8
    d = canonical_camera(plate)
    assert set(d) == {"position", "focal_point", "view_up"}
    assert Camera.from_dict(d) == canonical_view(plate.vertices, plate.faces)
    with pytest.raises(ValueError, match="unknown camera preset"):
        preset_view(plate.vertices, "top")
    with pytest.raises(ValueError, match="unknown up axis"):
        canonical_view(plate.vertices, up="w")


def test_silhouette_of_a_box_mesh_picks_its_broad_side():
    import trimesh

    box = trimesh.creation.box(extents=(0.5, 2.0, 4.0))  # thin in X, long in Z
    v, f = trimesh.remesh.subdivide_to_size(box.vertices, box.faces, max_edge=0.1)
    cam = canonical_view(v, f, azimuth=0.0, elevation=0.0)
    assert np.allclose(cam.direction, [1, 0, 0], atol=1e-12)  # the 2 x 4 side
    assert np.allclose(cam.up, [0, 1, 0], atol=1e-12)
    # lying flat (thin in Y, the up axis): seen from above
    flat = v[:, [1, 0, 2]]
    assert np.allclose(canonical_view(flat, f, azimuth=0, elevation=0).direction, [0, 1, 0])


def test_r_resets_the_view_at_once(monkeypatch):
    """R right after a drag seemed not to reset the view on a large mesh: the canonical
    view was computed again on every R (seconds at 384k vertices), and the window drew
    nothing meanwhile.  It is computed once per up axis."""
    import modalviewer as mv
    from modalviewer.scene.mesh_scene import MeshScene
    from modalviewer.scene.offscreen import offscreen_plotter
    from modalviewer.viewer import camera

    calls = []
    real = camera.canonical_view
    monkeypatch.setattr(camera, "canonical_view", lambda *a, **k: calls.append(1) or real(*a, **k))
    spot = mv.load_mesh(mv.asset_path("spot.obj"))
    plotter = offscreen_plotter((200, 150))
    try:
        scene = MeshScene(plotter, spot)
        first = np.array(scene.reset_camera().direction)
        plotter.camera.Azimuth(40.0)  # a drag
        plotter.camera.Elevation(20.0)
        again = scene.reset_camera()
        cam = plotter.camera
        shown = np.subtract(cam.GetPosition(), cam.GetFocalPoint())
        assert np.allclose(shown / np.linalg.norm(shown), first, atol=1e-9)
        assert np.allclose(again.direction, first) and len(calls) == 1
        scene.up_axis = "+z"  # another up axis: its own view
        assert abs(scene.reset_camera().up[2]) > 0.9 and len(calls) == 2
    finally:
        plotter.close()


def test_a_camera_link_carries_turns_and_zooms_of_one_view_to_the_other():
    from modalviewer.viewer.camera import Camera, CameraLink

    a = Camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    b = Camera((10.0, 11.0, 1.0), (10.0, 1.0, 1.0), (1.0, 0.0, 0.0))  # elsewhere, 2x as far
    link = CameraLink.between(a, b)
    carried, factor = link.carry(a)
    assert np.allclose(carried.position, b.position) and np.allclose(carried.up, b.up)
    assert factor == pytest.approx(2.0)
    # A turned 90 degrees about its focal point (to look from +X) and brought closer:
    # B turns the same way relative to its own view, about its own focal point
    turned = Camera((2.5, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    moved, _ = link.carry(turned)
    assert np.allclose(moved.focal_point, b.focal_point)
    assert np.linalg.norm(np.subtract(moved.position, moved.focal_point)) == pytest.approx(5.0)
    assert np.allclose(moved.up, b.up)
    # A's right (+X) is B's right, rot @ x for the rotation taking A's frame to B's
    right_b = np.cross(np.subtract(b.focal_point, b.position), b.up)
    direction = np.subtract(moved.position, moved.focal_point) / 5.0
    assert np.allclose(direction, right_b / np.linalg.norm(right_b))
    back, inverse = link.carry(moved, from_a=False)
    assert np.allclose(back.position, turned.position) and inverse == pytest.approx(0.5)
