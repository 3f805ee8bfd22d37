"""The panels' line plots (spectrum, signature curves) on a matplotlib canvas."""

from __future__ import annotations

import warnings

import numpy as np
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator, NullFormatter
from qtpy import QtCore

FONT_SIZE = 8
"""Points, for every text of the plot: a dock is at most 340 pixels wide."""
LINE, SECOND, HIGHLIGHT = "#285ab4", "#e67814", "#dc2828"

# a plot squeezed below the size of its labels (a dock dragged small) keeps its last layout
warnings.filterwarnings("ignore", "constrained_layout not applied", UserWarning)


class LinePlot(FigureCanvasQTAgg):
    """Plots y against x with an optional highlighted sample; a click selects the sample
    nearest in x (``sampleClicked``)."""

    sampleClicked = QtCore.Signal(int)

    def __init__(self, title: str = "", xlabel: str = "", ylabel: str = "", parent=None):
        # the figure's size is the widget's size hint: as tall as the plot's minimum
        super().__init__(Figure(figsize=(2.0, 1.4), layout="constrained"))
        self.setParent(parent)
        self.setMinimumHeight(140)
        self.title, self.xlabel, self.ylabel = title, xlabel, ylabel
        self.ax = self.figure.add_subplot()
        self._shown = None  # what the axes were last built and laid out for (see draw)
        self.mpl_connect("button_press_event", self._on_press)
        self.set_data([], [])

    def set_data(self, x, y, highlight=None, logx=False, markers=True, title=None) -> None:
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.highlight, self.logx, self.markers = highlight, logx, markers
        self.second, self.second_label = None, ""
        if title is not None:
            self.title = title
        self.draw_idle()

    def set_second(self, y, label: str = "") -> None:
        """A second curve over the same x, drawn dashed in orange and named ``label`` in
        the legend (bottom left); None removes it."""
        self.second = None if y is None else np.asarray(y, dtype=float)
        self.second_label = label if y is not None else ""
        self.draw_idle()

    def draw(self) -> None:
        """Draw the data, once for all changes since the last draw (Qt draws when idle).
        A change of the highlight alone (a step to the next mode) draws its dot on the
        picture kept from the last full drawing; anything else rebuilds and lays out the
        axes.  A long title wraps between words; a short y label ("λ", "S_t") stands
        upright, a longer one reads upwards."""
        second = None if self.second is None else self.second.tobytes()
        shown = (self.title, self.xlabel, self.ylabel, self.logx, self.markers, self.x.tobytes())
        shown += (self.y.tobytes(), second, self.second_label, *self.figure.bbox.size)
        if shown != self._shown:
            self._shown = shown
            self._plot()
            super().draw()
            self._background = self.copy_from_bbox(self.figure.bbox)
        else:
            self.restore_region(self._background)
        if self.highlight is not None and 0 <= self.highlight < self.x.size:
            self._dot.set_data([self.x[self.highlight]], [self.y[self.highlight]])
            self.ax.draw_artist(self._dot)
        self.update()

    def _plot(self) -> None:
        ax = self.ax
        ax.clear()
        ax.set_title(self.title, fontsize=FONT_SIZE, wrap=True)
        ax.set_axis_on()
        self._dot = ax.plot([], [], "o", color=HIGHLIGHT, ms=7)[0]  # placed by draw()
        if self.x.size == 0:
            ax.set_axis_off()
            ax.text(0.5, 0.5, "no data", ha="center", va="center", transform=ax.transAxes)
            return
        ax.set_xscale("log" if self.logx else "linear")
        marker = "o" if self.markers and self.x.size <= 400 else None
        ax.plot(self.x, self.y, color=LINE, lw=1.5, marker=marker, ms=3)
        if self.second is not None and self.second.shape == self.x.shape:
            ax.plot(self.x, self.second, "--", color=SECOND, lw=1.5, label=self.second_label)
            ax.legend(loc="lower left", fontsize=FONT_SIZE, frameon=False)
        if self.logx:  # labels at powers of ten only: a narrow dock has no room for more
            ax.xaxis.set_minor_formatter(NullFormatter())
        elif np.allclose(self.x, np.round(self.x)):  # mode indices
            ax.xaxis.set_major_locator(MaxNLocator(nbins=5, integer=True))
        ax.yaxis.set_major_locator(MaxNLocator(nbins=4))
        ax.tick_params(labelsize=FONT_SIZE)
        ax.set_xlabel(self.xlabel, fontsize=FONT_SIZE, loc="right")
        upright = len(self.ylabel) <= 3  # then it ends left of the tick labels, not centred
        align = {"rotation": 0, "ha": "right", "va": "center"} if upright else {}
        ax.set_ylabel(self.ylabel, fontsize=FONT_SIZE, **align)

    def _on_press(self, event) -> None:
        if self.x.size:
            xs = self.ax.transData.transform(np.column_stack([self.x, self.y]))[:, 0]
            self.sampleClicked.emit(int(np.argmin(np.abs(xs - event.x))))
