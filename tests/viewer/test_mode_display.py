"""How 3D vibration modes and colour ranges are drawn: the deformed shape with the rest
shape's ghost, and the symmetric, robust and typed colour ranges (off screen, no Qt)."""

from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import binary_erosion

from modalviewer.core.laplacian import lumped_masses
from modalviewer.scene.overlay import ColorBar, Overlay, draw_overlay
from modalviewer.viewer import Viewer

ASSETS = Path(__file__).resolve().parents[2] / "assets"
SIZE = (400, 300)


@pytest.fixture(scope="module")
def machined():
    v = Viewer()
    v.open_mesh(ASSETS / "demo_machined_part.obj")
    v.state.style.colorbar = False
    v.compute("shells", k=16)
    v.show_mode(8)
    yield v
    v.close()


def _ghost_visible(scene) -> bool:
    return scene.ghost_actor is not None and bool(scene.ghost_actor.GetVisibility())


def _silhouette(viewer) -> np.ndarray:
    """The shape's pixels, seen from the camera of the picture before (not fitted
    again: the deformed and the rest shape are compared in one frame)."""
    return viewer.image(transparent=True, size=SIZE, fit=False)[..., 3] > 0


def test_a_deformed_mode_export_differs_from_the_rest_shape(machined):
    state = machined.state
    assert state.style.shell_coloring == "deformed"  # the default
    state.style.ghost = False
    deformed = _silhouette(machined)
    state.style.shell_coloring = "normal"
    try:
        rest = _silhouette(machined)
        assert state.derived.field().deformation == 0.0
    finally:
        state.style.shell_coloring = "deformed"
        state.style.ghost = True
    changed = np.logical_xor(deformed, rest).sum() / np.logical_or(deformed, rest).sum()
    assert changed > 0.05, changed  # 17.5 % for mode 8 at the default amplitude


def test_the_amplitude_sets_the_largest_displacement(machined):
    state = machined.state
    diagonal = state.mesh.bounding_box_diagonal
    scene = machined.renderer(SIZE).scene
    largest = np.linalg.norm(scene.surface.points - scene.rest_points, axis=1).max()
    assert largest == pytest.approx(0.1 * diagonal, rel=1e-6)  # the default: a tenth
    state.animation.amplitude = 20
    try:
        largest = np.linalg.norm(scene.surface.points - scene.rest_points, axis=1).max()
        assert largest == pytest.approx(0.05 * diagonal, rel=1e-6)
        field = state.derived.field()
        assert field.colormap == "sequential"  # coloured by the displacement magnitude
        # of the mode itself, not of the drawn shape, and the legend says so
        assert "white 0 to red: |Phi| per vertex (Mass-normalised mode)" in field.legend
        np.testing.assert_allclose(
            field.values,
            np.linalg.norm(field.displacement, axis=1)
            * (np.linalg.norm(state.spectrum("shells").mode(8), axis=1).max()),
        )
    finally:
        state.animation.amplitude = 40


def test_the_ghost_of_the_rest_shape_can_be_hidden(machined):
    """The ghost shows where the rest shape is and the deformed shape is not (89 % of
    those pixels change; it fades at its edges), and never over the deformed surface.
    Where that had moved behind the rest shape the ghost greyed it over in patches
    before it was drawn at the back of the depth range: 20 % of this part's deformed
    surface in mode 8, 30 % of the teapot's in its mode 21 and 14 % of the cow Loop x2's
    in its mode 10 changed with the ghost."""
    state = machined.state
    state.style.ghost = True
    with_ghost = machined.image(size=SIZE).astype(int)
    scene = machined.renderer(SIZE).scene
    assert _ghost_visible(scene)
    assert "grey: rest shape" in state.derived.field().legend
    state.style.ghost = False
    try:
        without = machined.image(size=SIZE, fit=False).astype(int)
        assert not _ghost_visible(scene)
        deformed = _silhouette(machined)
        state.style.shell_coloring = "normal"
        rest = _silhouette(machined)
    finally:
        state.style.shell_coloring = "deformed"
        state.style.ghost = True
    changed = np.abs(with_ghost - without).max(axis=2) > 8
    beside = rest & ~deformed
    assert beside.sum() > 1000, beside.sum()
    assert changed[beside].mean() > 0.6, changed[beside].mean()
    inside = binary_erosion(deformed, iterations=2)  # not the antialiased outline
    assert changed[inside].mean() < 0.002, changed[inside].mean()
    # a mode on the rest shape has no ghost
    state.style.shell_coloring = "magnitude"
    try:
        machined.image(size=SIZE)
        assert not _ghost_visible(scene)
    finally:
        state.style.shell_coloring = "deformed"


def test_the_ghost_lies_behind_where_the_surface_barely_moves(machined):
    """At amplitude 1 (the largest displacement a four-hundredth of the diagonal) the
    deformed surface nearly coincides with the rest shape's ghost: drawn behind it and
    faded out there, the ghost leaves the picture as it is without it.  Where the two
    fought for the pixels, pale blotches showed on the parts a mode barely moves."""
    state = machined.state
    scene = machined.renderer(SIZE).scene
    state.animation.amplitude = 1
    try:
        state.style.ghost = True
        with_ghost = machined.image(size=SIZE).astype(int)
        assert _ghost_visible(scene)
        state.style.ghost = False
        without = machined.image(size=SIZE, fit=False).astype(int)
    finally:
        state.style.ghost = True
        state.animation.amplitude = 40
    changed = (np.abs(with_ghost - without).max(axis=2) > 8).mean()
    assert changed < 0.002, changed


def test_old_settings_asking_for_automatic_get_the_deformed_shape(machined):
    state = machined.state
    state.style.shell_coloring = "normal"
    state.style.shell_coloring = "auto"
    assert state.style.shell_coloring == "deformed"


def _weighted_percentile(values, weights, percent):
    a = np.abs(values)
    order = np.argsort(a)
    share = np.cumsum(weights[order]) / weights.sum()
    return a[order][np.argmax(share >= percent / 100.0)]


@pytest.fixture(scope="module")
def spot():
    v = Viewer()
    v.open_mesh(ASSETS / "spot.obj")
    v.compute("shells", k=30)
    v.pick_vertex(2000)
    v.show_distance("vibration", display="continuous")
    yield v
    v.close()


def test_automatic_colours_of_3d_modes_keep_one_rule_from_mode_to_mode(machined):
    """Stepping through 3D modes drawn as deformed shapes (|Phi|, white to red), the
    automatic range is the largest |value| for every mode, so a colour means the same
    share of a mode's largest displacement on each (not spread by area on some)."""
    state = machined.state
    assert state.style.color_range == "auto"
    rules = []
    for mode in range(6, 16):
        machined.show_mode(mode)
        field = state.derived.field()
        assert field.colormap == "sequential"
        rules.append(field.color_range)
        assert field.clim == (0.0, pytest.approx(float(np.max(np.abs(field.values)))))
    assert set(rules) == {"symmetric"}, rules


def test_the_robust_range_clips_at_the_99th_area_weighted_percentile(spot):
    state = spot.state
    assert state.style.color_range == "auto"
    assert state.derived.field().color_range == "spread"  # this distance is crowded low
    state.set_color_range("robust")
    field = state.derived.field()
    d = state.derived.distance_map()
    hi = _weighted_percentile(d, lumped_masses(state.mesh), 99.0)
    assert field.clim == (0.0, pytest.approx(hi, rel=1e-12))
    assert hi < d.max()
    assert field.clipped == (False, True)
    assert "robust range: 99th percentile" in field.legend
    assert f"> {hi:.3g} clipped" in field.legend
    scene = spot.renderer(SIZE).scene
    spot.image(size=SIZE)
    bar = scene.colorbar()
    assert bar.clipped == (False, True) and bar.clim[1] == pytest.approx(hi)
    # the symmetric range: up to the largest value, nothing clipped
    state.set_color_range("symmetric")
    try:
        field = state.derived.field()
        assert field.clim == (0.0, pytest.approx(d.max()))
        assert field.clipped == (False, False)
        spot.image(size=SIZE)
        assert scene.colorbar().clipped == (False, False)
    finally:
        state.set_color_range("auto")


def test_the_colour_bar_marks_clipped_ends():
    blank = np.full((120, 400, 3), 255, np.uint8)
    colors = [np.array([1.0, 1.0, 1.0]), np.array([0.78, 0.08, 0.08])]
    plain = draw_overlay(blank, Overlay(None, ColorBar("d", colors, (0.0, 1.0))))
    marked = draw_overlay(
        blank, Overlay(None, ColorBar("d", colors, (0.0, 1.0), clipped=(False, True)))
    )
    both = draw_overlay(
        blank, Overlay(None, ColorBar("d", colors, (0.0, 1.0), clipped=(True, True)))
    )
    # the bar spans the middle half: an arrow head beyond its right end, then its left
    right = slice(301, 312)
    left = slice(88, 99)
    assert (plain[:, right] != marked[:, right]).any()
    assert (plain[:, left] == marked[:, left]).all()
    assert (marked[:, left] != both[:, left]).any()
    red = np.all(np.abs(marked[:, right].astype(int) - [199, 20, 20]) < 30, axis=-1)
    assert red.sum() > 10  # the arrow head in the end's colour


def test_round_off_at_a_colour_bar_end_reads_0():
    """A range from 2.02e-16 (round-off of a magnitude that is 0 somewhere) to 2.19 is
    labelled as the range from 0: the same picture; a real small end keeps its digits."""
    blank = np.full((120, 400, 3), 255, np.uint8)
    colors = [np.array([1.0, 1.0, 1.0]), np.array([0.78, 0.08, 0.08])]

    def drawn(lo):
        return draw_overlay(blank, Overlay(None, ColorBar("d", colors, (lo, 2.19))))

    assert np.array_equal(drawn(2.02e-16), drawn(0.0))
    assert not np.array_equal(drawn(0.00581), drawn(0.0))


def test_typed_colour_limits(spot):
    state = spot.state
    d = state.derived.distance_map()
    lo, hi = 0.2 * d.max(), 0.6 * d.max()
    state.set_color_range("limits", (lo, hi))
    try:
        field = state.derived.field()
        assert field.clim == (pytest.approx(lo), pytest.approx(hi))
        assert field.clipped == (True, True)
        assert f"range: limits {lo:.3g} .. {hi:.3g}" in field.legend
        spot.image(size=SIZE)
        assert spot.renderer(SIZE).scene.clim == pytest.approx((lo, hi))
    finally:
        state.set_color_range("auto")
    assert state.style.color_limits == (lo, hi)  # kept for the next "limits"
    with pytest.raises(ValueError, match="low < high"):
        state.set_color_range("limits", (1.0, 1.0))


def test_cli_render_draws_a_shells_mode_deformed(tmp_path):
    from PIL import Image

    from modalviewer.cli import main

    masks = {}
    for show in ("deformed", "normal"):
        out = tmp_path / f"{show}.png"
        argv = ["render", str(ASSETS / "demo_machined_part.obj"), "--operator", "shells"]
        argv += ["--mode", "8", "-k", "16", "--size", "400x300", "--transparent"]
        assert main([*argv, "--show", show, "-o", str(out)]) == 0
        masks[show] = np.asarray(Image.open(out))[..., 3] > 0
    a, b = masks["deformed"], masks["normal"]
    assert np.logical_xor(a, b).sum() / np.logical_or(a, b).sum() > 0.05


def test_sessions_keep_the_mode_display_and_colour_range(spot, tmp_path):
    import json

    state = spot.state
    state.style.ghost = False
    state.set_color_range("limits", (0.0, 2.0))
    path = spot.save_session(tmp_path / "s.json")
    state.style.ghost = True
    state.set_color_range("auto")
    data = json.loads(path.read_text())
    assert data["style"]["ghost"] is False and data["style"]["color_limits"] == [0.0, 2.0]
    again = Viewer()
    try:
        again.open_session(path)
        assert again.state.style.ghost is False
        assert again.state.style.color_range == "limits"
        assert again.state.style.color_limits == (0.0, 2.0)
        # a session from before: "auto" colouring, no ghost or colour range saved
        data["style"] = {"isolines": 12, "shell_coloring": "auto", "render": "paper"}
        path.write_text(json.dumps(data))
        again.open_session(path)
        style = again.state.style
        assert (style.shell_coloring, style.ghost, style.color_range) == (
            "deformed",
            True,
            "auto",
        )
    finally:
        again.close()


def test_the_ghost_fades_where_the_surface_moved_slightly_behind_it():
    """A plate seen face on whose left half moves a hair away from the camera (0.3 % of
    the diagonal, beyond any depth offset) while its right half swings toward it: the
    ghost of the left half stands just in front of the surface there and would grey it
    over (the cow's flank in its tail mode).  It fades out where the surface moves less
    than GHOST_FADE, so the picture is as it is without it; where the right half moved
    out the ghost is behind the surface, hidden.  Without the fading 50 % of the plate's
    pixels change."""
    from modalviewer.core.laplacian import vertex_normals
    from modalviewer.core.primitives import grid_plate
    from modalviewer.scene.mesh_scene import GHOST_FADE, GHOST_OPACITY, MeshScene
    from modalviewer.scene.offscreen import offscreen_plotter
    from modalviewer.scene.view import draw_field
    from modalviewer.viewer.derived import Field

    mesh = grid_plate(40, 40)  # the unit square in the XY plane
    x = mesh.vertices[:, 0]
    reach = 0.1 * mesh.bounding_box_diagonal  # the default amplitude's largest motion
    behind = 0.03  # of the largest displacement: 0.3 % of the diagonal
    assert behind * 0.1 < GHOST_FADE[0]
    shape = np.where(x < 0.5, -behind, -behind + (1 + behind) * np.clip(2 * x - 1, 0, 1))
    displacement = np.zeros((mesh.n_vertices, 3))
    displacement[:, 2] = shape  # toward the camera on +z
    light_blue = np.full(mesh.n_vertices, 0.5)
    field = Field(light_blue, "diverging", clim=(-1.0, 1.0), deformation=reach)
    field.displacement = displacement
    plotter = offscreen_plotter((400, 300))
    try:
        scene = MeshScene(plotter, mesh, vertex_normals(mesh))
        scene.reset_camera("+z")
        pictures = []
        for ghost in (True, False):
            field.ghost = ghost
            draw_field(scene, field)
            assert _ghost_visible(scene) == ghost
            plotter.render()
            pictures.append(plotter.screenshot(return_img=True).astype(int))
        plate = np.abs(pictures[1] - 255).max(axis=2) > 8
        changed = (np.abs(pictures[0] - pictures[1]).max(axis=2) > 8)[plate].mean()
        assert plate.mean() > 0.2, plate.mean()
        assert changed < 0.01, changed  # 0.0 % with the fading ghost
        # the ghost itself: full where the right half moved far, none on the left half
        opacities = scene.ghost_opacities(reach)
        assert opacities[x < 0.5].max() == 0.0
        assert opacities[x > 0.75].min() == pytest.approx(GHOST_OPACITY)
    finally:
        plotter.close()
