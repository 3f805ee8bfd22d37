"""The legend and colour bar of an exported picture, drawn with Pillow onto the rendered
image at the export's scale (VTK's tiled rendering of a scaled screenshot repeats or
overlaps 2D text; drawing the overlay afterwards keeps text size, placement and a
transparent background right at any scale).  No Qt, no VTK.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

FONT_PX = 14  # text height at scale 1, in pixels
MARGIN_PX = 10


@dataclass
class ColorBar:
    """A colour bar: ``kind`` "continuous" (a gradient through ``colors`` from clim[0] to
    clim[1], labelled at both ends and at 0 when the range straddles it) or "swatches"
    (one square per colour, labelled by ``labels``).  ``clipped`` (low, high): values lie
    beyond that end of a continuous bar; the end gets an arrow head in its colour and its
    label a "<" or ">"."""

    title: str
    colors: list = field(default_factory=list)  # RGB in [0, 1]
    clim: tuple[float, float] = (0.0, 1.0)
    kind: str = "continuous"
    labels: list = field(default_factory=list)
    clipped: tuple[bool, bool] = (False, False)
    ticks: list = field(default_factory=list)  # (value, position 0..1): a spread scale's


@dataclass
class Overlay:
    legend: str | None = None
    colorbar: ColorBar | None = None

    def __bool__(self) -> bool:
        return bool(self.legend) or self.colorbar is not None


def _font(size: float):
    from PIL import ImageFont

    return ImageFont.load_default(size=max(6, round(size)))


def _rgba(c) -> tuple[int, int, int, int]:
    c = np.clip(np.asarray(c, dtype=float), 0.0, 1.0)
    return (*(int(round(255 * x)) for x in c[:3]), 255)


def colorbar_label(value: float, scale: float = 0.0) -> str:
    """A colour-bar tick label: 3 significant digits; "0" for zero and for round-off
    (at most 1e-9 of ``scale``, the bar's largest |value|)."""
    return "0" if abs(value) <= 1e-9 * scale else f"{value:.3g}"


def wrap_text(text: str, measure, width: float) -> str:
    """``text`` broken at spaces so that ``measure(line) <= width``.  No-break spaces hold
    words together and come out as plain spaces (the default font has no glyph for them)."""
    nbsp = "\u00a0"
    out = []
    for line in text.split("\n"):
        current = ""
        for word in line.split(" "):
            candidate = f"{current} {word}" if current else word
            if current and measure(candidate.replace(nbsp, " ")) > width:
                out.append(current)
                current = word
            else:
                current = candidate
        out.append(current)
    return "\n".join(out).replace(nbsp, " ")


def draw_overlay(img: np.ndarray, overlay: Overlay | None, scale: float = 1.0) -> np.ndarray:
    """``img`` (h, w, 3 or 4) uint8 with the legend at the top left and the colour bar at
    the bottom drawn on it, a copy (``img`` itself where ``overlay`` is empty or None).
    Sizes are ``scale`` times the on-screen ones."""
    from PIL import Image, ImageDraw

    if not overlay:
        return img
    mode = "RGBA" if img.shape[2] == 4 else "RGB"
    canvas = Image.fromarray(np.ascontiguousarray(img), mode)
    draw = ImageDraw.Draw(canvas)
    s = float(scale)
    h, w = img.shape[:2]
    margin, em, line_gap = MARGIN_PX * s, FONT_PX * s, 0.35 * FONT_PX * s
    font = _font(em)
    black, outline = (0, 0, 0, 255), max(1, round(s))

    def measure(text: str) -> float:
        return draw.textlength(text, font=font)

    def write(xy, text: str) -> None:
        draw.multiline_text(xy, text, fill=black, font=font, spacing=line_gap)

    if overlay.legend:
        write((margin, margin), wrap_text(overlay.legend, measure, w - 2 * margin))
    bar = overlay.colorbar
    if bar is None:
        return np.asarray(canvas)
    if bar.kind == "swatches":
        labels = [
            wrap_text(label, measure, w - 2 * margin - 1.6 * em)
            for label in bar.labels[: len(bar.colors)]
        ]
        lines = sum(label.count("\n") + 1 for label in labels)
        y = h - margin - lines * (em + line_gap)
        if bar.title:
            title = wrap_text(bar.title, measure, w - 2 * margin)
            write((margin, y - (title.count("\n") + 1) * (em + line_gap)), title)
        for color, label in zip(bar.colors, labels, strict=False):
            box = [margin, y, margin + em, y + em]
            draw.rectangle(box, fill=_rgba(color), outline=black, width=outline)
            write((margin + 1.6 * em, y), label)
            y += (label.count("\n") + 1) * (em + line_gap)
        return np.asarray(canvas)
    width, height = min(0.5 * w, 320 * s), 0.9 * em
    x0 = 0.5 * (w - width)
    y_labels = h - margin - em
    y1 = y_labels - 0.4 * em
    y0 = y1 - height
    n = max(2, int(round(width)))
    t, anchors = np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, len(bar.colors))
    rgb = np.column_stack([np.interp(t, anchors, [c[i] for c in bar.colors]) for i in range(3)])
    for i, color in enumerate(rgb):
        draw.rectangle([x0 + width * i / n, y0, x0 + width * (i + 1) / n, y1], fill=_rgba(color))
    draw.rectangle([x0, y0, x0 + width, y1], outline=black, width=outline)
    # arrow heads past clipped ends (matplotlib's "extend"), in the end's colour
    tip = 0.8 * height
    for end, x_end, sign in ((0, x0, -1.0), (1, x0 + width, 1.0)):
        if bar.clipped[end]:
            head = [(x_end, y0), (x_end + sign * tip, 0.5 * (y0 + y1)), (x_end, y1)]
            draw.polygon(head, fill=_rgba(rgb[-1 if end else 0]), outline=black, width=outline)
    lo, hi = bar.clim
    ticks = [(lo, 0.0), (hi, 1.0)] + ([(0.0, (0.0 - lo) / (hi - lo))] if lo < 0 < hi else [])
    if bar.ticks:  # a spread scale: its values where they lie on the bar
        ticks = [(float(v), float(p)) for v, p in bar.ticks]
        for _, pos in ticks:
            x = x0 + pos * width
            draw.line([(x, y1), (x, y1 + 0.3 * em)], fill=black, width=1)
    for value, pos in ticks:
        text = colorbar_label(value, max(abs(lo), abs(hi)))
        if pos in (0.0, 1.0) and bar.clipped[int(pos)]:
            text = ("> " if pos else "< ") + text
        tw = measure(text)
        write((np.clip(x0 + pos * width - 0.5 * tw, 0, w - tw), y_labels), text)
    if bar.title:
        write((max(0.0, 0.5 * (w - measure(bar.title))), y0 - 1.4 * em), bar.title)
    return np.asarray(canvas)
