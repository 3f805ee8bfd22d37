"""A comparison (:class:`~modalviewer.viewer.comparison.Comparison`) drawn off screen."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .export import grab, save_png, side_by_side
from .mesh_scene import MeshScene
from .offscreen import offscreen_plotter
from .view import draw_field, label_field

VIEW_SIZE = (480, 480)
"""Pixels of each view unless a size is given."""


def caption(img: np.ndarray, text: str) -> np.ndarray:
    """``img`` with ``text`` written in a white band above it."""
    from PIL import Image, ImageDraw

    from .overlay import FONT_PX, _font, wrap_text

    width = img.shape[1]
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    font = _font(FONT_PX)
    text = wrap_text(text, lambda t: probe.textlength(t, font=font), width - 16)
    lines = text.count("\n") + 1
    mode = "RGBA" if img.shape[2] == 4 else "RGB"  # opaque white either way
    band = Image.new(mode, (width, int(lines * FONT_PX * 1.35 + 12)), "white")
    ImageDraw.Draw(band).multiline_text((8, 6), text, fill="black", font=font)
    return np.vstack([np.asarray(band), img])


def save_comparison(comparison, path, size=VIEW_SIZE, camera=None, scale: int = 1) -> Path:
    """Write the views of ``comparison`` side by side, each captioned with its title, to a
    PNG atomically, all seen by ``camera`` (default the mesh's canonical first view)."""
    state = comparison.state
    images = []
    for view in comparison.views():
        plotter = offscreen_plotter(size)
        try:
            scene = MeshScene(plotter, state.mesh, state.derived.normals, style=state.style.render)
            draw_field(scene, view.field)
            label_field(scene, view.field)
            scene.show_marker(view.marker)
            scene.set_camera(camera or scene.canonical_camera())
            images.append(caption(grab(plotter, scene, scale=scale), view.title))
        finally:
            plotter.close()
    return save_png(path, side_by_side(images, gap=4 * scale))
