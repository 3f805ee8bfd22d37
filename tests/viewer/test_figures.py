"""Figures written to files: animations of a mode (GIF, MP4), pictures at a chosen size
with the shape clear of the legend, the pick marker on distance maps only (off screen,
no Qt)."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import modalviewer as mv
from modalviewer.cli import main
from modalviewer.scene.animation import mp4_available
from modalviewer.scene.export import grab
from modalviewer.scene.framing import overlay_boxes
from modalviewer.viewer import Viewer

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture(scope="module")
def spot():
    v = Viewer()
    v.open_mesh(ASSETS / "spot.obj")
    v.compute("shells", k=12)
    v.compute("laplacian", k=12)
    yield v
    v.close()


def _gif_frames(path) -> list[np.ndarray]:
    with Image.open(path) as image:
        frames = []
        for i in range(image.n_frames):
            image.seek(i)
            frames.append(np.asarray(image.convert("RGB")))
    return frames


def _shape(img: np.ndarray) -> np.ndarray:
    """Pixels that are not the white background (some channel below 245)."""
    return (img[..., :3] < 245).any(axis=2)


def test_a_shells_gif_has_the_frames_and_size_asked_for_and_its_silhouette_moves(spot, tmp_path):
    spot.show_mode(8, "shells")
    path = spot.export_animation(tmp_path / "mode8.gif", frames=12, fps=10, size=(320, 240))
    with Image.open(path) as image:
        assert image.n_frames == 12
        assert image.size == (320, 240)
        assert image.info["duration"] == 100  # 10 frames per second
        assert image.info["loop"] == 0  # loops for ever
    frames = _gif_frames(path)
    changes = [
        np.abs(a.astype(int) - b.astype(int)).sum()
        for a, b in zip(frames, frames[1:] + frames[:1], strict=True)
    ]
    assert min(changes) > 0  # every frame differs from the next, the last from the first
    # frame 0 is the largest displacement (phase pi/2), frame 6 the opposite one: the
    # silhouettes differ by a good share of their area
    a, b = _shape(frames[0]), _shape(frames[6])
    moved = np.logical_xor(a, b).sum() / np.logical_or(a, b).sum()
    assert moved > 0.05, moved


def test_a_scalar_modes_colours_change_sign_over_the_period(spot, tmp_path):
    spot.show_mode(5, "laplacian")
    frames = spot.animation_images(frames=8, size=(480, 360))
    # orange (red high, blue low) and blue (blue high) pixels of the surface trade places
    # between the two extremes (phases pi/2 and 3 pi/2)
    # (above the colour bar, whose ends are orange and blue in every frame)
    first, opposite = (f[:290].astype(int) for f in (frames[0], frames[4]))

    def orange(img):
        return (img[..., 0] - img[..., 2]) > 60

    def blue(img):
        return (img[..., 2] - img[..., 0]) > 60

    assert orange(first).sum() > 300 and blue(first).sum() > 300
    same = np.logical_and(orange(first), orange(opposite)).sum() / orange(first).sum()
    swapped = np.logical_and(orange(first), blue(opposite)).sum() / orange(first).sum()
    assert swapped > 0.5 and same < 0.1, (swapped, same)


def test_an_animation_needs_a_mode_and_a_gif_or_mp4_name(spot, tmp_path):
    spot.show_mode(5, "laplacian")
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        spot.export_animation(tmp_path / "mode.avi", frames=4)
    assert not (tmp_path / "mode.avi").exists()
    spot.state.set_display(kind="curvature")
    try:
        with pytest.raises(ValueError, match="show a mode first"):
            spot.export_animation(tmp_path / "curvature.gif", frames=4)
    finally:
        spot.show_mode(5, "laplacian")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not mp4_available(), reason="imageio-ffmpeg is not installed")
def test_an_mp4_has_the_frames_and_size_asked_for(spot, tmp_path):
    import imageio.v3 as iio

    spot.show_mode(8, "shells")
    path = spot.export_animation(tmp_path / "mode8.mp4", frames=10, fps=20, size=(320, 240))
    frames = iio.imread(path)
    assert frames.shape == (10, 240, 320, 3)
    assert np.abs(frames[0].astype(int) - frames[5].astype(int)).mean() > 1.0
    with pytest.raises(ValueError, match="even"):
        spot.export_animation(tmp_path / "odd.mp4", frames=4, size=(321, 240))


def test_the_default_animation_plays_one_period_at_the_windows_speed(spot):
    spot.show_mode(8, "shells")
    spot.state.animation.speed = 50  # 5 rad/s: a period of 1.26 s
    try:
        frames = spot.animation_images(fps=10, size=(64, 48))
    finally:
        spot.state.animation.speed = 30
    assert len(frames) == round(2 * np.pi / 5.0 * 10)  # 13


def test_render_animate_writes_a_gif(tmp_path, capsys):
    out = tmp_path / "mode3.gif"
    args = ["render", str(ASSETS / "demo_plate.obj"), "--operator", "shells", "-k", "8"]
    args += ["--mode", "6", "--animate", "--frames", "6", "--size", "200x150", "-o", str(out)]
    assert main(args) == 0
    assert "GIF 200x150, 6 frames" in capsys.readouterr().out
    with Image.open(out) as image:
        assert (image.n_frames, image.size) == (6, (200, 150))


def test_render_animate_refuses_a_png_name_before_any_work(tmp_path, capsys):
    out = tmp_path / "mode3.png"
    args = ["render", str(ASSETS / "demo_plate.obj"), "--mode", "3", "--animate", "-o", str(out)]
    assert main(args) == 2
    assert ".gif or .mp4" in capsys.readouterr().err


def test_plot_animate_returns_a_gif_shown_inline(spot, tmp_path):
    spec = spot.state.spectrum("laplacian")
    anim = mv.plot(spot.mesh, spec, mode=4, animate=True, frames=5, size=(160, 120))
    assert len(anim.frames) == 5 and anim.size == (160, 120)
    assert anim.data[:6] == b"GIF89a"
    assert anim._repr_html_().startswith('<img src="data:image/gif;base64,')
    path = anim.save(tmp_path / "plot.gif")
    with Image.open(path) as image:
        assert image.n_frames == 5


def test_a_picture_at_a_chosen_size_holds_the_shape_clear_of_legend_and_bar(spot, tmp_path):
    spot.show_mode(8, "shells")  # deformed, over its ghost
    spot.state.style.colorbar = True
    path = spot.export_screenshot(tmp_path / "big.png", size=(1600, 1200))
    with Image.open(path) as image:
        assert image.size == (1600, 1200)
    renderer = spot.renderer()
    # the same camera without legend and bar: where the shape is
    bare = grab(renderer.plotter, renderer.scene, legend=False, colorbar=False)
    shape = _shape(bare)
    (lw, lh), bottom = overlay_boxes(1600, 1200, renderer.scene.overlay())
    assert lh > 0 and bottom > 0
    assert not shape[:lh, :lw].any()  # nothing under the legend
    assert not shape[1200 - bottom :].any()  # nothing under the colour bar
    assert not shape[:, :3].any() and not shape[:, -3:].any()  # inside the frame
    rows, cols = np.flatnonzero(shape.any(1)), np.flatnonzero(shape.any(0))
    # and it fills the free part: at least 80 % of the free height or width
    free_w = 1600 - (lw if cols.min() >= lw else 0)
    free_h = 1200 - bottom - (lh if rows.min() >= lh else 0)
    assert max(np.ptp(rows) / free_h, np.ptp(cols) / free_w) > 0.8


def test_the_pick_marker_shows_on_distance_maps_and_not_on_modes(spot, tmp_path):
    spot.show_mode(5, "laplacian")
    spot.image(size=(800, 600))
    renderer = spot.renderer()
    renderer.plotter.render()
    vertex = renderer.scene.vertex_at_display(400, 300)  # in the middle of the view
    assert vertex is not None
    spot.pick_vertex(vertex, show=False)

    def magenta(img):  # the marker's colour, shaded: red and blue well above green
        r, g, b = (img[..., i].astype(int) for i in range(3))
        return ((r - g > 90) & (b - g > 40)).sum()

    assert magenta(spot.image(size=(800, 600))) == 0
    assert magenta(spot.image(size=(800, 600), marker=True)) > 20
    spot.show_distance("hks", display="continuous")
    assert magenta(spot.image(size=(800, 600))) > 20
    assert magenta(spot.image(size=(800, 600), marker=False)) == 0


def _scale_positions(img: np.ndarray) -> np.ndarray:
    """The position (0 white .. 1 red) on the white-to-red scale of each surface pixel
    of a transparent picture, undoing the shading (which scales all three channels):
    colour = (1 - t) white + t (0.78, 0.08, 0.08), so green / red = (1 - 0.92 t) /
    (1 - 0.22 t)."""
    surface = img[..., 3] > 0
    r = np.maximum(img[..., 0][surface].astype(float), 1.0)
    q = np.clip(img[..., 1][surface] / r, 0.0, 1.0)
    return np.clip((1.0 - q) / (0.92 - 0.22 * q), 0.0, 1.0)


def _largest_tenth(viewer) -> float:
    img = viewer.image(size=(640, 480), transparent=True, marker=False)
    t = _scale_positions(img)
    return float(np.bincount(np.minimum((t * 10).astype(int), 9), minlength=10).max() / t.size)


def test_a_continuous_distance_map_spreads_its_colours_over_the_visible_surface(spot):
    """spot's vibration distance from a vertex on its flank: the robust linear range
    leaves most of the visible surface in its lowest tenth; the automatic range spreads
    the colours by area, so no tenth of the scale covers more than a quarter of the
    surface's pixels, and the colour bar's ticks are the true distances."""
    spot.state.style.colorbar = False  # the bar's own colours are not the surface's
    spot.pick_vertex(1500, show=False)
    spot.show_distance("vibration", display="continuous")
    try:
        field = spot.state.derived.field()
        assert field.color_range == "spread"
        spread = _largest_tenth(spot)
        spot.state.set_color_range("robust")
        linear = _largest_tenth(spot)
    finally:
        spot.state.set_color_range("auto")
        spot.state.style.colorbar = True
    assert spread < 0.25 < linear, (spread, linear)
    bar = spot.renderer().scene.colorbar()
    d = spot.state.derived.distance_map()
    ticks = dict((p, v) for v, p in bar.ticks)
    assert ticks[0.0] == pytest.approx(d.min()) and ticks[1.0] == pytest.approx(d.max())
    areas = spot.state.derived.vertex_areas()
    # the middle tick is the distance below which half the surface's area lies
    assert areas[d <= ticks[0.5]].sum() / areas.sum() == pytest.approx(0.5, abs=0.03)


def test_render_modes_writes_a_grid_with_one_camera_and_one_colour_bar(tmp_path, capsys):
    out = tmp_path / "row.png"
    args = ["render", str(ASSETS / "spot.obj"), "--operator", "laplacian", "-k", "12"]
    args += ["--modes", "1-8", "--grid", "4x2", "--size", "1200x700", "-o", str(out)]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "8 modes" in printed and "lambda 1: " in printed
    img = np.asarray(Image.open(out))
    assert img.shape[:2] == (700, 1200)  # the size asked for, panels and bar included
    # one colour bar: the orange-white-blue gradient, 320 pixels wide in the middle of
    # a row of the strip below the panels; no panel has its own
    from modalviewer.scene.colors import COLORMAPS

    def deviation(row_pixels, x0, width=320):
        xs = np.arange(int(x0) + 3, int(x0 + width) - 3)
        t = (xs + 0.5 - x0) / width
        colors = COLORMAPS["diverging"]
        anchors = np.linspace(0, 1, len(colors))
        want = np.column_stack([np.interp(t, anchors, [c[i] for c in colors]) for i in range(3)])
        return np.abs(row_pixels[xs, :3].astype(float) - 255 * want).max()

    w = img.shape[1]
    best = {y: deviation(img[y], 0.5 * (w - 320)) for y in range(img.shape[0])}
    bar_rows = [y for y, dev in best.items() if dev < 12]
    assert bar_rows and min(bar_rows) > img.shape[0] - 60, bar_rows
    assert max(bar_rows) - min(bar_rows) < 14  # one bar, about 13 pixels high


def test_a_mode_grid_shares_its_camera_and_restores_the_display(spot):
    spot.show_mode(3, "laplacian")
    before = spot.state.display
    img = spot.mode_grid([1, 2, 3], "laplacian", size=(200, 180))
    assert spot.state.display == before
    assert spot.state.style.color_range == "auto"
    assert img.shape[1] == 3 * 200 + 2 * 4
    with pytest.raises(ValueError, match="between 0 and 11"):
        spot.mode_grid([3, 40], "laplacian")


def test_plot_modes_draws_a_grid(spot):
    spec = spot.state.spectrum("laplacian")
    picture = mv.plot(spot.mesh, spec, modes=[1, 2], size=(200, 160))
    assert picture.shape[1] == 2 * 200 + 4
