"""Several modes side by side in one picture (the paper's rows of modes).  No Qt."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

GRID_PANEL = (400, 340)
"""Pixels of each panel of a mode grid unless a size is given."""


def grid_shape(count: int, grid=None) -> tuple[int, int]:
    """(columns, rows) for ``count`` panels: ``grid`` if it has room, else rows of up to 4."""
    if grid is not None:
        columns, rows = (int(x) for x in grid)
        if columns < 1 or rows < 1 or columns * rows < count:
            raise ValueError(
                f"a {columns}x{rows} grid has {columns * rows} cells for {count} modes"
            )
        return columns, rows
    columns = min(count, 4)
    return columns, math.ceil(count / columns)


def arrange(images: list[np.ndarray], columns: int, gap: int = 4) -> np.ndarray:
    """``images`` (equal sizes, RGB) in rows of ``columns`` on a white canvas."""
    h, w = images[0].shape[:2]
    rows = math.ceil(len(images) / columns)
    canvas = np.full((rows * h + (rows - 1) * gap, columns * w + (columns - 1) * gap, 3), 255)
    canvas = canvas.astype(np.uint8)
    for i, img in enumerate(images):
        r, c = divmod(i, columns)
        canvas[r * (h + gap) : r * (h + gap) + h, c * (w + gap) : c * (w + gap) + w] = img[..., :3]
    return canvas


def bar_strip(width: int, colorbar, scale: float = 1.0) -> np.ndarray:
    """A white strip ``width`` pixels wide holding ``colorbar`` as a picture's bottom does."""
    from .framing import overlay_boxes
    from .overlay import Overlay, draw_overlay

    overlay = Overlay(None, colorbar)
    tall = np.full((400, int(width), 3), 255, np.uint8)
    _, bottom = overlay_boxes(int(width), 400, overlay, scale)
    strip = draw_overlay(tall, overlay, scale)[400 - bottom - 6 :]
    return np.ascontiguousarray(strip)


CAPTION_PX = 31
"""Rows of a one-line caption above a panel (:func:`.comparison.caption` at scale 1)."""

BAR_PX = 66
"""Rows of the colour bar's strip below the panels, at most."""


def panel_size(total, count: int, grid=None, gap: int = 4) -> tuple[int, int]:
    """The panel size of a captioned grid of ``count`` panels fitting in ``total`` pixels."""
    columns, rows = grid_shape(count, grid)
    w = (int(total[0]) - gap * (columns - 1)) // columns
    h = (int(total[1]) - BAR_PX - rows * CAPTION_PX - gap * (rows - 1)) // rows
    if w < 16 or h < 16:
        raise ValueError(f"{total[0]}x{total[1]} is too small for {columns}x{rows} panels")
    return w, h


def padded(img: np.ndarray, total) -> np.ndarray:
    """``img`` at the top left of a white canvas of ``total`` pixels (a grid's rounding)."""
    w, h = int(total[0]), int(total[1])
    if img.shape[1] > w or img.shape[0] > h:
        return img
    canvas = np.full((h, w, 3), 255, np.uint8)
    canvas[: img.shape[0], : img.shape[1]] = img[..., :3]
    return canvas


def mode_grid(viewer, modes, operator: str | None = None, grid=None, size=GRID_PANEL):
    """``modes`` of ``operator`` (default the one shown) drawn as the viewer draws them, in
    ``grid`` panels of ``size`` captioned with mode number and eigenvalue: one camera
    fitted to all of them, one colour range and bar; RGB uint8."""
    from ..core.operators import operator_info
    from .comparison import caption
    from .export import grab
    from .framing import fit_points
    from .offscreen import OffscreenRenderer
    from .overlay import ColorBar

    state = viewer.state
    op = operator or viewer.state.current_operator()
    spec = state.spectrum(op) if op is not None else None
    if spec is None:
        raise ValueError("compute a spectrum first: a mode grid shows its modes")
    modes = [int(j) for j in modes]
    bad = [j for j in modes if not 0 <= j < spec.k]
    if not modes or bad:
        raise ValueError(f"modes must be between 0 and {spec.k - 1}, got {bad or 'none'}")
    columns, _ = grid_shape(len(modes), grid)
    display, style = state.display, state.style
    saved_range = (style.color_range, style.color_limits)
    camera = viewer.current_camera()
    renderer = OffscreenRenderer(state, tuple(int(x) for x in size))
    try:
        renderer.set_camera(camera)
        fields, points = [], []
        for j in modes:
            state.show_mode(j, op)
            field = renderer.drawing.field
            fields.append(field)
            points.append(renderer.scene.motion_points(field.deformation, both=False))
        largest = max(float(np.max(np.abs(f.values))) for f in fields) or 1.0
        signed = fields[0].colormap == "diverging"
        limits = (-largest, largest) if signed else (0.0, largest)
        state.set_color_range("limits", limits)
        fit_points(renderer.plotter.renderer, np.concatenate(points), renderer.size)
        panels = []
        for j in modes:
            state.show_mode(j, op)
            img = grab(renderer.plotter, renderer.scene, legend=False, colorbar=False, marker=False)
            lam = "0 (zero mode)" if spec.zero_mode_mask()[j] else f"{spec.eigenvalues[j]:.4g}"
            panels.append(caption(img[..., :3], f"mode {j}: lambda = {lam}"))
        field = renderer.drawing.field
    finally:
        renderer.close()
        state.set_color_range(*saved_range)
        state.style.color_limits = saved_range[1]  # none where none had been typed
        state.set_display(**dataclasses.asdict(display))
    canvas = arrange(panels, columns)
    title = f"{operator_info(op).label}: {'deformed shapes, ' if field.deformation else ''}"
    title += "colours over one range"
    from .colors import COLORMAPS

    shared = ColorBar(title, [np.asarray(c) for c in COLORMAPS[field.colormap]], limits)
    return np.vstack([canvas, bar_strip(canvas.shape[1], shared)])
