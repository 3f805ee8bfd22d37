"""A small, fast line plot drawn with QPainter (spectrum, signature curves)."""

from __future__ import annotations

import numpy as np
from qtpy import QtCore, QtGui, QtWidgets


class LinePlot(QtWidgets.QWidget):
    """Plots y against x with an optional highlighted sample; click selects a sample."""

    sampleClicked = QtCore.Signal(int)

    def __init__(self, title: str = "", xlabel: str = "", ylabel: str = "", parent=None):
        super().__init__(parent)
        self.title, self.xlabel, self.ylabel = title, xlabel, ylabel
        self.x = np.zeros(0)
        self.y = np.zeros(0)
        self.highlight: int | None = None
        self.logx = False
        self.markers = True
        self.setMinimumHeight(140)

    def set_data(self, x, y, highlight=None, logx=False, markers=True, title=None) -> None:
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.highlight = highlight
        self.logx = logx
        self.markers = markers
        if title is not None:
            self.title = title
        self.update()

    def set_highlight(self, index: int | None) -> None:
        self.highlight = index
        self.update()

    def _transform(self):
        x = np.log10(self.x) if self.logx else self.x
        y = self.y
        x0, x1 = float(x.min()), float(x.max())
        y0, y1 = float(y.min()), float(y.max())
        # room for the longer of the two axis labels (e.g. "-4.75e-08" for a zero mode)
        metrics = self.fontMetrics()
        left = 8 + max(metrics.horizontalAdvance(f"{v:.3g}") for v in (y0, y1))
        rect = self.rect().adjusted(max(46, left), 20, -10, -28)
        if x1 == x0:
            x1 = x0 + 1
        if y1 == y0:
            y1 = y0 + 1
        px = rect.left() + (x - x0) / (x1 - x0) * rect.width()
        py = rect.bottom() - (y - y0) / (y1 - y0) * rect.height()
        return rect, px, py, (y0, y1)

    def paintEvent(self, event):  # noqa: N802
        p = QtGui.QPainter(self)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        p.fillRect(self.rect(), QtGui.QColor("white"))
        p.setPen(QtGui.QColor("black"))
        p.drawText(6, 14, self.title)
        if self.x.size == 0:
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "no data")
            p.end()
            return
        rect, px, py, (y0, y1) = self._transform()
        p.setPen(QtGui.QColor(150, 150, 150))
        p.drawRect(rect)
        p.setPen(QtGui.QColor("black"))
        p.drawText(2, rect.top() + 10, f"{y1:.3g}")
        p.drawText(2, rect.bottom(), f"{y0:.3g}")
        p.drawText(rect.left(), rect.bottom() + 16, self.xlabel)
        p.setPen(QtGui.QPen(QtGui.QColor(40, 90, 180), 1.5))
        path = QtGui.QPainterPath(QtCore.QPointF(px[0], py[0]))
        for a, b in zip(px[1:], py[1:], strict=True):
            path.lineTo(a, b)
        p.drawPath(path)
        if self.markers and len(px) <= 400:
            p.setBrush(QtGui.QColor(40, 90, 180))
            for a, b in zip(px, py, strict=True):
                p.drawEllipse(QtCore.QPointF(a, b), 1.8, 1.8)
        if self.highlight is not None and 0 <= self.highlight < len(px):
            p.setPen(QtGui.QPen(QtGui.QColor(220, 40, 40), 2))
            p.setBrush(QtGui.QColor(220, 40, 40))
            p.drawEllipse(QtCore.QPointF(px[self.highlight], py[self.highlight]), 4, 4)
        p.end()

    def mousePressEvent(self, event):  # noqa: N802
        if self.x.size == 0:
            return
        _, px, _, _ = self._transform()
        self.sampleClicked.emit(int(np.argmin(np.abs(px - event.position().x()))))
