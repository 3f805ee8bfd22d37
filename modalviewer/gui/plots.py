"""A small, fast line plot drawn with QPainter (spectrum, signature curves)."""

from __future__ import annotations

import numpy as np
from qtpy import QtCore, QtGui, QtWidgets


def axis_label(value: float, scale: float) -> str:
    """A tick label with 3 significant digits; values below 1e-8 times ``scale`` (the
    axis' largest magnitude), round-off around a zero eigenvalue, read "0"."""
    if abs(value) <= 1e-8 * scale:
        return "0"
    return f"{value:.3g}"


def nice_ticks(lo: float, hi: float, count: int = 5) -> np.ndarray:
    """About ``count`` round tick positions (1, 2 or 5 times a power of ten) in [lo, hi]."""
    if not np.isfinite(lo) or not np.isfinite(hi) or hi <= lo:
        return np.array([lo])
    raw = (hi - lo) / max(count, 1)
    power = 10.0 ** np.floor(np.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    first = np.ceil(lo / step - 1e-9) * step
    return np.arange(first, hi + 1e-9 * step, step) + 0.0  # + 0.0: no "-0"


def _polygon(xs, ys) -> QtGui.QPolygonF:
    return QtGui.QPolygonF([QtCore.QPointF(x, y) for x, y in zip(xs, ys, strict=True)])


TITLE_MARGIN = 6
"""Pixels between the title and the plot's left and right edges."""


class LinePlot(QtWidgets.QWidget):
    """Plots y against x with an optional highlighted sample; click selects a sample."""

    sampleClicked = QtCore.Signal(int)

    def __init__(self, title: str = "", xlabel: str = "", ylabel: str = "", parent=None):
        super().__init__(parent, minimumHeight=140)
        self.title, self.xlabel, self.ylabel = title, xlabel, ylabel
        self.set_data([], [])

    def set_data(self, x, y, highlight=None, logx=False, markers=True, title=None) -> None:
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.highlight = highlight
        self.logx = logx
        self.markers = markers
        self.second, self.second_label = None, ""
        if title is not None:
            self.title = title
        self.update()

    def set_second(self, y, label: str = "") -> None:
        """A second curve over the same x, drawn dashed in orange and named ``label``
        (bottom left); None removes it."""
        self.second = None if y is None else np.asarray(y, dtype=float)
        self.second_label = label if y is not None else ""
        self.update()

    def title_lines(self) -> list[str]:
        """The title in lines no wider than the plot less its margins: broken between
        words (inside a word only if it alone is wider), so no character is cut off."""
        layout = QtGui.QTextLayout(self.title, self.font())
        option = QtGui.QTextOption()
        option.setWrapMode(QtGui.QTextOption.WrapMode.WrapAtWordBoundaryOrAnywhere)
        layout.setTextOption(option)
        lines = []
        layout.beginLayout()
        while (line := layout.createLine()).isValid():
            line.setLineWidth(max(self.width() - 2 * TITLE_MARGIN, 1))
            start = line.textStart()
            lines.append(self.title[start : start + line.textLength()].strip())
        layout.endLayout()
        return [line for line in lines if line]

    def _transform(self):
        x = np.log10(self.x) if self.logx else self.x
        y = self.y
        x0, x1 = float(x.min()), float(x.max())
        both = y if self.second is None else np.concatenate([y, self.second])
        y0, y1 = float(both.min()), float(both.max())
        # room for the longer of the two axis labels (e.g. "-4.75e-08" for a zero mode)
        metrics = self.fontMetrics()
        scale = max(abs(y0), abs(y1))
        left = 8 + max(metrics.horizontalAdvance(axis_label(v, scale)) for v in (y0, y1))
        # the frame starts below the title's last line
        top = 20 + (max(len(self.title_lines()), 1) - 1) * metrics.lineSpacing()
        rect = self.rect().adjusted(max(46, left), top, -10, -34)
        y1 = y1 if y1 > y0 else y0 + 1  # a flat curve: along the bottom of a unit range
        px = rect.left() + (x - x0) / ((x1 - x0) or 1) * rect.width()

        def to_py(values):
            return rect.bottom() - (values - y0) / (y1 - y0) * rect.height()

        self._second_py = None if self.second is None else to_py(self.second)
        return rect, px, to_py(y), (y0, y1)

    def x_ticks(self, rect=None) -> list[tuple[float, float]]:
        """(value, pixel x) of the tick labels along the bottom: round numbers (integers
        for integer samples such as mode indices), powers of ten on a log axis."""
        if self.x.size == 0:
            return []
        if rect is None:
            rect = self._transform()[0]
        x = np.log10(self.x) if self.logx else self.x
        x0, x1 = float(x.min()), float(x.max())
        span = (x1 - x0) or 1.0
        count = max(2, min(6, rect.width() // 60))
        if self.logx:
            ticks = np.arange(np.ceil(x0 - 1e-9), np.floor(x1 + 1e-9) + 1)
            if ticks.size > count:
                ticks = ticks[:: int(np.ceil(ticks.size / count))]
            values = 10.0**ticks
        else:
            ticks = nice_ticks(x0, x1, count)
            if np.allclose(self.x, np.round(self.x)):
                ticks = np.unique(np.round(ticks))
            values = ticks
        return [
            (float(v), rect.left() + (t - x0) / span * rect.width())
            for v, t in zip(values, ticks, strict=True)
        ]

    def paintEvent(self, event):  # noqa: N802
        p = QtGui.QPainter(self)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        p.fillRect(self.rect(), QtGui.QColor("white"))
        p.setPen(QtGui.QColor("black"))
        spacing = self.fontMetrics().lineSpacing()
        for i, line in enumerate(self.title_lines()):
            p.drawText(TITLE_MARGIN, 14 + i * spacing, line)
        if self.x.size == 0:
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "no data")
            p.end()
            return
        rect, px, py, (y0, y1) = self._transform()
        p.setPen(QtGui.QColor(150, 150, 150))
        p.drawRect(rect)
        p.setPen(QtGui.QColor("black"))
        scale = max(abs(y0), abs(y1))
        p.drawText(2, rect.top() + 10, axis_label(y1, scale))
        p.drawText(2, rect.bottom(), axis_label(y0, scale))
        metrics = self.fontMetrics()
        for value, xpos in self.x_ticks(rect):
            text = f"1e{round(np.log10(value))}" if self.logx else axis_label(value, 1.0)
            w = metrics.horizontalAdvance(text)
            xpos_text = min(max(xpos - w / 2, rect.left() - 4), self.width() - w - 2)
            p.setPen(QtGui.QColor(150, 150, 150))
            p.drawLine(QtCore.QPointF(xpos, rect.bottom()), QtCore.QPointF(xpos, rect.bottom() + 3))
            p.setPen(QtGui.QColor("black"))
            p.drawText(QtCore.QPointF(xpos_text, rect.bottom() + 15), text)
        p.drawText(
            rect.right() - metrics.horizontalAdvance(self.xlabel), rect.bottom() + 30, self.xlabel
        )
        self._draw_ylabel(p, rect)
        p.setPen(QtGui.QPen(QtGui.QColor(40, 90, 180), 1.5))
        p.drawPolyline(_polygon(px, py))
        if self._second_py is not None and len(self._second_py) == len(px):
            p.setPen(QtGui.QPen(QtGui.QColor(230, 120, 20), 1.5, QtCore.Qt.PenStyle.DashLine))
            p.drawPolyline(_polygon(px, self._second_py))
            p.drawText(rect.left() + 4, rect.bottom() - 4, self.second_label)
        if self.markers and len(px) <= 400:
            p.setBrush(QtGui.QColor(40, 90, 180))
            for a, b in zip(px, py, strict=True):
                p.drawEllipse(QtCore.QPointF(a, b), 1.8, 1.8)
        if self.highlight is not None and 0 <= self.highlight < len(px):
            p.setPen(QtGui.QPen(QtGui.QColor(220, 40, 40), 2))
            p.setBrush(QtGui.QColor(220, 40, 40))
            p.drawEllipse(QtCore.QPointF(px[self.highlight], py[self.highlight]), 4, 4)
        p.end()

    def _draw_ylabel(self, p: QtGui.QPainter, rect: QtCore.QRect) -> None:
        """The y axis's name in the left margin, between the value labels at the frame's
        top and bottom: as it is where it fits the margin's width ("λ", "S_t"), else
        turned to read upwards and elided to the room between the value labels."""
        if not self.ylabel:
            return
        metrics = self.fontMetrics()
        middle = rect.center().y()
        if metrics.horizontalAdvance(self.ylabel) <= rect.left() - 6:
            p.drawText(2, middle + metrics.ascent() // 2, self.ylabel)
            return
        room = rect.height() - 2 * metrics.height()
        text = metrics.elidedText(self.ylabel, QtCore.Qt.TextElideMode.ElideRight, room)
        if room <= 0 or not text:
            return
        p.save()
        p.translate(2 + metrics.ascent(), middle + metrics.horizontalAdvance(text) / 2)
        p.rotate(-90)
        p.drawText(0, 0, text)
        p.restore()

    def mousePressEvent(self, event):  # noqa: N802
        if self.x.size == 0:
            return
        _, px, _, _ = self._transform()
        self.sampleClicked.emit(int(np.argmin(np.abs(px - event.position().x()))))
