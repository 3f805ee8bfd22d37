"""Pixels of the rendering style, legend and colour bar on exported screenshots, the bold
zero line's filter, and the permissions of exported files (scene level, off-screen)."""

import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

import modalviewer as mv
from modalviewer.core.laplacian import vertex_normals
from modalviewer.core.primitives import icosphere
from modalviewer.io import load_mesh

pytestmark = pytest.mark.gui
ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture(scope="module")
def spot_mode():
    mesh = load_mesh(ASSETS / "spot.obj")
    spec = mv.compute_spectrum(mesh, "laplacian", k=8)
    return mesh, spec.mode(6), spec.mode(1)


@pytest.fixture
def view():
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=(480, 400))
    plotter.set_background("white")
    plotter.show(auto_close=False, interactive=False)
    yield SimpleNamespace(plotter=plotter)
    plotter.close()


def _scene(view, mesh, style="paper"):
    from modalviewer.scene.mesh_scene import MeshScene

    scene = MeshScene(view.plotter, mesh, vertex_normals(mesh), style=style)
    scene.reset_camera()
    return scene


def _export(view, path, **kwargs):
    from modalviewer.scene.export import grab, save_png

    out = save_png(path, grab(view.plotter, **kwargs))
    return np.asarray(Image.open(out))


def _measure(view, scene, field, tmp_path):
    from benchmarks.render_metrics import saturation, white_level, zero_band_masks

    scene.show_field(field, "diverging", isolines=0)
    img = _export(view, tmp_path / f"{scene.style}.png")[:, :, :3]
    mesh_px, band = zero_band_masks(scene, field)
    assert band.sum() > 300 and mesh_px.sum() > 20000, (band.sum(), mesh_px.sum())
    return white_level(img, band), saturation(img, mesh_px)


def test_paper_style_white_zero_and_saturated_colours(view, spot_mode, tmp_path):
    mesh, _, field = spot_mode  # mode 1: blue at one end, orange at the other
    scene = _scene(view, mesh, "paper")
    white, sat = _measure(view, scene, field, tmp_path)
    # the zero band facing the viewer (normal within 45 degrees of the view): every
    # channel at least 225 on 95 % of its pixels (measured 246; shaded style 185)
    assert white["p5"] >= 225, white
    # blue 60 above red on 28 % of the mesh's pixels, orange on 30 % (shaded: 20, 22 %)
    assert sat["blue"] > 0.24 and sat["orange"] > 0.26, sat
    scene.set_style("shaded")
    shaded_white, shaded_sat = _measure(view, scene, field, tmp_path)
    assert shaded_white["p5"] < 200, shaded_white
    assert shaded_sat["blue"] < sat["blue"], (shaded_sat, sat)


def test_paper_style_darkens_toward_silhouettes(view, spot_mode, tmp_path):
    """Shape stays readable: surfaces seen at a grazing angle render clearly darker."""
    from benchmarks.render_metrics import _flat_render, facing

    mesh, field, _ = spot_mode
    scene = _scene(view, mesh, "paper")
    scene.show_field(np.zeros(mesh.n_vertices), "diverging", isolines=0)  # all white
    img = _export(view, tmp_path / "white.png")[:, :, :3].astype(int)
    grazing = ~facing(scene, 0.35)
    flat = _flat_render(scene, grazing).astype(int)
    mask_grazing = (flat[:, :, 1] > 250) & (flat[:, :, 0] < 5)
    mask_front = (flat[:, :, 0] > 250) & (flat[:, :, 1] < 5)
    assert mask_grazing.sum() > 1000
    brightness = img.max(axis=2)
    assert np.median(brightness[mask_front]) >= 250
    assert np.median(brightness[mask_grazing]) < 200, np.median(brightness[mask_grazing])


def test_unknown_style_is_refused(view, spot_mode):
    scene = _scene(view, spot_mode[0])
    with pytest.raises(ValueError, match="unknown style"):
        scene.set_style("glossy")


def _dark(img, box, base):
    """Number of dark opaque pixels in box = (x0, y0, x1, y1) (fractions of the size)
    that are not in ``base``, the same export without legend and colour bar."""
    h, w = img.shape[:2]
    x0, y0, x1, y1 = int(box[0] * w), int(box[1] * h), int(box[2] * w), int(box[3] * h)
    part = img[y0:y1, x0:x1].astype(int)
    dark = part[:, :, :3].max(axis=2) < 100
    if part.shape[2] == 4:
        dark &= part[:, :, 3] > 128
    dark &= np.any(part != base[y0:y1, x0:x1], axis=2)
    return int(dark.sum())


@pytest.mark.parametrize("scale", [1, 2])
def test_legend_in_exports_with_and_without_colour_bar(view, spot_mode, tmp_path, scale):
    mesh, field, _ = spot_mode
    scene = _scene(view, mesh)
    scene.show_field(field, "diverging", isolines=0, name="Laplacian mode 6")
    legend_box = (0.0, 0.0, 0.45, 0.12)
    bottom = (0.2, 0.8, 0.8, 1.0)
    plain = _export(view, tmp_path / "plain.png", scale=scale, transparent=True)
    assert plain.shape == (400 * scale, 480 * scale, 4)
    scene.set_legend("Laplacian, mode 6: lambda = 12.3\nblue +, white 0, orange -")
    for colorbar in (False, True):
        img = _export(view, tmp_path / "l.png", scale=scale, transparent=True, colorbar=colorbar)
        # text at the top left, its size proportional to the scale
        assert _dark(img, legend_box, plain) > 150 * scale**2, _dark(img, legend_box, plain)
        # transparent background stays transparent beside the text
        assert img[-1, -1, 3] == 0 and img[0, -1, 3] == 0
        bar = _dark(img, bottom, plain)
        if colorbar:
            assert bar > 60 * scale**2, bar
        else:
            assert bar == 0, bar
    scene.set_colorbar("Laplacian mode 6")  # shown on screen: exported by default
    base = _export(view, tmp_path / "b.png", scale=scale, legend=False, colorbar=False)
    on_screen = _export(view, tmp_path / "c.png", scale=scale)
    assert _dark(on_screen, bottom, base) > 60 * scale**2
    no_legend = _export(view, tmp_path / "n.png", scale=scale, legend=False)
    assert _dark(no_legend, legend_box, base) == 0


def test_threshold_map_legend_follows_the_colour_bar_option(view, spot_mode, tmp_path):
    mesh, field, _ = spot_mode
    scene = _scene(view, mesh)
    marked = (field > np.quantile(field, 0.3)).astype(float)  # 1 = not similar
    scene.show_field(marked, "threshold", name="vibration distance < 0.12")
    scene.set_legend("blue: vibration distance < 0.12, 8.4 % of the surface")
    scene.set_colorbar("vibration distance < 0.12", labels=["< 0.12", ">= 0.12"])
    swatch_box = (0.0, 0.8, 0.4, 1.0)

    def swatch_blue(img):
        h, w = img.shape[:2]
        part = img[int(0.8 * h) :, : int(0.12 * w)].astype(int)
        return int(((part[:, :, 2] > part[:, :, 0] + 60) & (part[:, :, 3] > 128)).sum())

    base = _export(view, tmp_path / "t.png", transparent=True, legend=False, colorbar=False)
    with_bar = _export(view, tmp_path / "t1.png", transparent=True, colorbar=True)
    without = _export(view, tmp_path / "t0.png", transparent=True, colorbar=False)
    assert swatch_blue(with_bar) > 50 and _dark(with_bar, swatch_box, base) > 50
    assert swatch_blue(without) == 0 and _dark(without, swatch_box, base) == 0
    for img in (with_bar, without):
        assert _dark(img, (0.0, 0.0, 0.6, 0.1), base) > 100  # the legend in both


def test_zero_line_absent_where_the_mode_is_dead(view):
    """A field that is x z^3 on the upper hemisphere (a nodal line along the meridian
    x = 0) and round-off noise (1e-6 of its maximum) on the lower: the bold zero line
    keeps the meridian where the field around it is meaningful and drops the noise."""
    mesh = icosphere(4)
    v = mesh.vertices
    rng = np.random.default_rng(1)
    top = v[:, 0] * np.maximum(v[:, 2], 0.0) ** 3
    field = np.where(v[:, 2] > 0, top, 3e-7 * rng.standard_normal(len(v)))
    scene = _scene(view, mesh)
    scene.show_field(field, "diverging", isolines=6)
    zero = np.asarray(scene._zero_rest).reshape(-1, 3)
    assert len(zero) > 20  # the real nodal line
    h = 0.07  # about one edge length of the level-4 sphere
    assert np.all(zero[:, 2] > 0.1), zero[:, 2].min()  # measured 0.13 (0.27 at 1 %)
    assert np.all(np.abs(zero[:, 0]) < h), np.abs(zero[:, 0]).max()
    # the thin isolines are unchanged by the filter: none in the dead half either way
    iso = np.asarray(scene._iso_rest).reshape(-1, 3)
    assert len(iso) > 100 and np.all(iso[:, 2] > -h)
    # without the filter the noise draws zero crossings all over the lower hemisphere
    tri = np.arange(mesh.n_faces)
    keep = _meaningful(scene, field, tri)
    low = v[mesh.faces].mean(axis=1)[:, 2] < -h
    assert keep[low].sum() == 0 and keep[~low].sum() > 100


def test_zero_line_of_a_low_mode_on_a_fine_mesh_is_kept(view):
    """Next to the line of a smooth low mode on a fine mesh the corner values are small;
    the gradient term keeps every segment of it."""
    mesh = icosphere(5)
    field = mesh.vertices[:, 2] * 1e-3  # any amplitude: the rule is relative
    scene = _scene(view, mesh)
    tri = np.arange(mesh.n_faces)
    fv = field[mesh.faces]
    crossed = tri[(fv.min(axis=1) < 0) & (fv.max(axis=1) >= 0)]
    assert _meaningful(scene, field, crossed).all()


@pytest.mark.parametrize("umask", [0o022, 0o027])
def test_exported_files_get_the_umask_permissions(view, spot_mode, tmp_path, umask):
    from modalviewer.scene.export import save_field_mesh

    mesh, field, _ = spot_mode
    _scene(view, mesh)
    old = os.umask(umask)
    try:
        png = tmp_path / "shot.png"
        _export(view, png)
        vtp = save_field_mesh(tmp_path / "field.vtp", mesh, {"f": field})
    finally:
        os.umask(old)
    for path in (png, vtp):
        assert (path.stat().st_mode & 0o777) == 0o666 & ~umask, oct(path.stat().st_mode)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no leftovers


def test_threshold_map_from_distances_moves_with_the_lookup_table_only(view, spot_mode):
    mesh, _, _ = spot_mode
    v = mesh.vertices
    d = np.linalg.norm(v - v[np.argmax(v[:, 0])], axis=1)  # a vertex on the seen side
    scene = _scene(view, mesh)

    def blue_pixels():
        view.plotter.render()
        img = np.asarray(view.plotter.screenshot(None, return_img=True)).astype(int)
        return int((img[:, :, 2] > img[:, :, 0] + 60).sum())

    scene.show_threshold(d, 0.2 * d.max(), name="distance < t")
    field = scene.surface.point_data["field"]
    assert np.array_equal(field, d)
    counts = [blue_pixels()]
    for t in (0.4, 0.6):
        scene.set_threshold(t * d.max())
        counts.append(blue_pixels())
        assert np.array_equal(scene.surface.point_data["field"], d)
    assert 500 < counts[0] < counts[1] < counts[2], counts
    assert scene.colorbar() is None  # until the caller asks for the swatches
    scene.set_colorbar("distance < t")
    assert scene.colorbar().kind == "swatches"


def test_a_threshold_far_below_the_largest_distance_moves_the_map(view, spot_mode):
    """Distances with a far tail (a thin part unlike the rest: the cow's tail from its
    flank, 1.25 against a median of 0.003): thresholds within a two-thousandth of the
    largest distance still move the blue region, and it covers the vertices below the
    threshold.  A table spread from 0 to the largest distance drew every such threshold
    as its first entry, the same picture for 3.5 % to 30 % of the surface."""
    mesh, _, _ = spot_mode
    v = mesh.vertices
    d = np.linalg.norm(v - v[np.argmax(v[:, 0])], axis=1)  # a vertex on the seen side
    far = d.copy()
    far[np.argmin(v[:, 0])] = 5000 * d.max()  # one vertex on the far side, unseen
    scene = _scene(view, mesh)

    def blue_pixels():
        view.plotter.render()
        img = np.asarray(view.plotter.screenshot(None, return_img=True)).astype(int)
        return int((img[:, :, 2] > img[:, :, 0] + 60).sum())

    counts, reference = [], []
    for share in (0.2, 0.4, 0.6):
        scene.show_threshold(far, share * d.max(), name="distance < t")
        counts.append(blue_pixels())
        scene.show_threshold(d, share * d.max(), name="distance < t")
        reference.append(blue_pixels())
    assert 500 < counts[0] < counts[1] < counts[2], counts
    for c, r in zip(counts, reference, strict=True):
        assert abs(c - r) <= 0.02 * r, (counts, reference)


def test_a_long_legend_wraps_inside_the_export(view, spot_mode, tmp_path):
    """A legend longer than a narrow export is wide wraps at spaces instead of running
    off the right edge."""
    mesh, field, _ = spot_mode
    scene = _scene(view, mesh)
    scene.show_field(field, "diverging", isolines=0, name="mode 9")
    plain = _export(view, tmp_path / "plain.png", legend=False, colorbar=False)
    scene.set_legend(
        "Discrete Shells, normal variations, mode 9: lambda = 2.373e+04 "
        "(coarse-to-fine: approximate)\nblue +, white 0, orange -"
    )
    img = _export(view, tmp_path / "long.png", colorbar=False)
    h, w = img.shape[:2]
    assert w == 480
    right_edge = (1.0 - 12 / w, 0.0, 1.0, 0.2)  # the last 12 pixels of the top fifth
    assert _dark(img, right_edge, plain) == 0
    third_line = (0.0, 0.09, 0.6, 0.14)  # the wrapped first line needs a second row
    assert _dark(img, third_line, plain) > 30


def test_wrap_text_breaks_at_spaces_within_the_width():
    from modalviewer.scene.overlay import wrap_text

    text = "aaa bbb ccc ddd\nee"
    wrapped = wrap_text(text, len, 7)
    assert wrapped == "aaa bbb\nccc ddd\nee"
    assert wrap_text("averyveryverylongword x", len, 5) == "averyveryverylongword\nx"
    # a no-break space keeps "22 %" on one line and is drawn as a plain space
    assert wrap_text("up to 22\u00a0%", len, 8) == "up to\n22 %"


def test_a_narrow_picture_keeps_the_swatch_labels_inside():
    """Found in a 168-pixel-wide export of a threshold map: the swatch label read
    "vibration distance < 0", its value cut off at the right edge.  Labels now wrap."""
    from modalviewer.scene.overlay import FONT_PX, ColorBar, Overlay, draw_overlay

    w, h = 168, 400
    bar = ColorBar(
        "",
        [(0.2, 0.4, 0.9), (1.0, 1.0, 1.0)],
        (0.0, 1.0),
        "swatches",
        ["vibration distance < 0.23", "the rest"],
    )
    img = draw_overlay(np.full((h, w, 3), 255, np.uint8), Overlay(None, bar))
    ink = (img < 128).all(axis=2)
    cols = np.flatnonzero(ink.any(axis=0))
    assert cols.size > 0 and cols.max() < w - 1, cols.max()  # nothing reaches the edge
    rows = np.flatnonzero(ink.any(axis=1))
    # three lines of text: the first label on two
    assert rows.max() - rows.min() > 2.5 * FONT_PX
    assert rows.max() < h - 1
    # a wide picture keeps each label on one line
    wide = draw_overlay(np.full((h, 600, 3), 255, np.uint8), Overlay(None, bar))
    rows_wide = np.flatnonzero((wide < 128).all(axis=2).any(axis=1))
    assert rows_wide.max() - rows_wide.min() < rows.max() - rows.min()


def test_zero_line_of_a_mode_dwarfed_by_a_far_peak_is_kept(view):
    """A mode whose peak lies far from its zero line (the cow Loop x2's first Laplacian
    mode: its tail peak, the body's line 0.35 to 0.92 % of it at the crossed triangles'
    corners) keeps its line: a bump of height 1 at the north pole over 0.05 x, which
    changes sign along x = 0 on the southern half (0.35 % at an edge's length from it).
    At 1 % the line was dropped."""
    mesh = icosphere(4)
    v = mesh.vertices
    bump = np.exp(-30.0 * np.sum((v - [0.0, 0.0, 1.0]) ** 2, axis=1))
    field = bump + 0.05 * v[:, 0]
    scene = _scene(view, mesh)
    scene.show_field(field, "diverging", isolines=6)
    zero = np.asarray(scene._zero_rest).reshape(-1, 3)
    south = zero[zero[:, 2] < -0.3]
    assert len(south) > 20, len(south)
    assert np.all(np.abs(south[:, 0]) < 0.07)  # along x = 0, within an edge


def _meaningful(scene, field, triangles):
    from modalviewer.scene.isolines import meaningful_zero

    m = scene.mesh
    return meaningful_zero(m.faces, scene.rest_points, field, triangles, m.bounding_box_diagonal)
