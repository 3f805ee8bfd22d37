"""The panels' line plots, checked on the pixels drawn: points where the values are, the
mode shown marked, zero modes read 0, tick labels, wrapped titles, the y axis's name."""

import numpy as np
import pytest
from qtpy import QtCore

from modalviewer.gui.plots import LinePlot

pytestmark = pytest.mark.gui

LAM = np.array([0.0, 0.0, 2.0, 5.0, 9.0, 14.0, 20.0, 27.0, 35.0, 44.0])


def _plot(qtbot, size, *args, **data) -> LinePlot:
    plot = LinePlot(*args)
    qtbot.addWidget(plot)
    plot.resize(*size)
    if data:
        plot.set_data(**data)
    plot.grab()  # resized and drawn: the layout is the one on screen
    return plot


def _box(plot, artist) -> tuple[float, float, float, float]:
    """``artist``'s extent in the widget's pixels: left, top, right, bottom."""
    box = artist.get_window_extent()
    ratio, height = plot.devicePixelRatioF(), plot.height()
    return box.x0 / ratio, height - box.y1 / ratio, box.x1 / ratio, height - box.y0 / ratio


def _pixel(plot, x, y) -> tuple[float, float]:
    """Data point (x, y) in the widget's pixels."""
    px, py = plot.ax.transData.transform((x, y)) / plot.devicePixelRatioF()
    return px, plot.height() - py


def _ink(image, xs, ys) -> list[tuple[int, int]]:
    return [(x, y) for y in ys for x in xs if image.pixelColor(x, y).lightness() < 100]


def _shown_ticks(axis, limits) -> list:
    lo, hi = sorted(limits)
    ticks = zip(axis.get_majorticklocs(), axis.get_majorticklabels(), strict=True)
    return [(value, label) for value, label in ticks if lo <= value <= hi]


def test_the_spectrum_is_drawn_where_the_eigenvalues_are_with_the_mode_shown_marked(qtbot):
    plot = _plot(qtbot, (360, 180), "Spectrum", "mode index", "λ")
    plot.set_data(np.arange(LAM.size), LAM, highlight=4)
    image = plot.grab().toImage()
    for i, lam in enumerate(LAM):
        x, y = _pixel(plot, i, lam)
        c = image.pixelColor(round(x), round(y))
        if i == 4:  # the mode shown: a red dot over the point
            assert c.red() > 180 and c.green() < 90 and c.blue() < 90, (i, c.name())
        else:  # a blue point
            assert c.blue() > 140 and c.red() < 110, (i, c.name())
    red = [
        (x, y)
        for y in range(image.height())
        for x in range(image.width())
        if (c := image.pixelColor(x, y)).red() > 180 and c.green() < 90 and c.blue() < 90
    ]
    x4, y4 = _pixel(plot, 4, LAM[4])
    assert len(red) > 10 and all(abs(x - x4) < 6 and abs(y - y4) < 6 for x, y in red)
    # the next mode (the highlight alone changes): the dot moves, the old place is blue
    plot.set_data(np.arange(LAM.size), LAM, highlight=7)
    image = plot.grab().toImage()
    for i, red in ((7, True), (4, False)):
        x, y = _pixel(plot, i, LAM[i])
        assert (image.pixelColor(round(x), round(y)).red() > 180) == red, i
    plot.set_data(np.arange(LAM.size), LAM)  # no mode shown: no mark
    image = plot.grab().toImage()
    for i in (4, 7):
        x, y = _pixel(plot, i, LAM[i])
        assert image.pixelColor(round(x), round(y)).red() < 110, i


def test_zero_modes_read_0_and_the_mode_indices_are_whole_numbers(qtbot):
    # the Modes panel passes zero modes as 0; their round-off is no label of its own
    plot = _plot(qtbot, (360, 180), "Spectrum", "mode index", "eigenvalue")
    plot.set_data(np.arange(LAM.size), LAM)
    image = plot.grab().toImage()
    ax = plot.ax
    xticks = _shown_ticks(ax.xaxis, ax.get_xlim())
    assert [v for v, _ in xticks] == [0, 2, 4, 6, 8]
    assert [t.get_text() for _, t in xticks] == ["0", "2", "4", "6", "8"]
    few = _plot(qtbot, (360, 180), x=np.arange(3), y=LAM[:3])  # no tick between two modes
    assert [v for v, _ in _shown_ticks(few.ax.xaxis, few.ax.get_xlim())] == [0, 1, 2]
    yticks = _shown_ticks(ax.yaxis, ax.get_ylim())
    assert yticks[0][0] == 0 and yticks[0][1].get_text() == "0"
    assert all("e" not in t.get_text() for _, t in yticks)
    assert not ax.yaxis.get_offset_text().get_text()
    # the tick labels are drawn in the band just below the frame
    left, top, right, bottom = _box(plot, ax.patch)
    below = range(int(bottom) + 4, int(bottom) + 17)
    band = _ink(image, range(int(left) - 4, int(right) + 4), below)
    assert len(band) > 30, len(band)


def test_a_click_selects_the_sample_nearest_in_x(qtbot):
    plot = _plot(qtbot, (360, 180), "Spectrum", "mode index", "λ")
    plot.set_data(np.arange(LAM.size), LAM)
    plot.grab()
    step = _pixel(plot, 1, 0)[0] - _pixel(plot, 0, 0)[0]
    assert step > 20
    for i, offset in ((0, 0.0), (6, 0.4), (7, -0.4), (9, 0.2)):
        x = round(_pixel(plot, i, LAM[i])[0] + offset * step)
        with qtbot.waitSignal(plot.sampleClicked, timeout=1000) as clicked:
            qtbot.mouseClick(plot, QtCore.Qt.MouseButton.LeftButton, pos=QtCore.QPoint(x, 40))
        assert clicked.args == [i]


def test_a_title_wider_than_the_plot_wraps_whole(qtbot):
    """Seen under Xvfb: "Spectrum (coarse-to-fine): Discrete Shells (3D vibrations" lost its
    ")" at the Modes dock's plot width (306 pixels at the default window size)."""
    title = "Spectrum (coarse-to-fine): Discrete Shells (3D vibrations)"
    inks = {}
    for width in (600, 306):
        plot = _plot(qtbot, (width, 140), x=np.arange(10), y=np.arange(10.0) ** 2, title=title)
        assert plot.ax.title.get_text() == title  # broken between words, nothing dropped
        _, _, _, title_bottom = _box(plot, plot.ax.title)
        assert _box(plot, plot.ax.patch)[1] > title_bottom  # the frame starts below it
        ink = inks[width] = _ink(plot.grab().toImage(), range(width), range(int(title_bottom) + 1))
        # the title's ink keeps off both edges
        assert 0 < min(x for x, _ in ink) and max(x for x, _ in ink) < width - 1
    rows = {width: sorted({y for _, y in ink}) for width, ink in inks.items()}
    # one line where it fits; two (a blank row between them) where it does not
    assert all(b == a + 1 for a, b in zip(rows[600], rows[600][1:], strict=False))
    assert any(b - a > 1 for a, b in zip(rows[306], rows[306][1:], strict=False))
    assert rows[306][-1] - rows[306][0] > 1.8 * (rows[600][-1] - rows[600][0])


@pytest.mark.parametrize("name", ["eigenvalue", "S_t", "W_E", ""])
def test_the_y_axis_is_named_in_the_left_margin(qtbot, name):
    """Left of the y tick labels, over the frame's height: a long name ("eigenvalue")
    reads upwards, a short one ("S_t", "λ") stands as it is, clear of the tick labels;
    without one no ink."""
    plot = _plot(qtbot, (360, 220), "Spectrum", "mode index", name, x=np.arange(9), y=LAM[1:])
    ax = plot.ax
    labels = [_box(plot, t) for _, t in _shown_ticks(ax.yaxis, ax.get_ylim())]
    _, top, _, bottom = _box(plot, ax.patch)
    image = plot.grab().toImage()
    ink = _ink(image, range(int(min(b[0] for b in labels)) - 1), range(int(top), int(bottom)))
    if not name:
        assert ink == []
        return
    width = max(x for x, _ in ink) - min(x for x, _ in ink)
    height = max(y for _, y in ink) - min(y for _, y in ink)
    name_right = _box(plot, ax.yaxis.label)[2]  # the name keeps clear of the tick labels
    assert name_right < min(b[0] for b in labels) - 1, (name_right, labels)
    if name == "eigenvalue":
        assert height > 3 * width, (width, height)
    else:
        assert width > height, (width, height)


def test_a_second_curve_is_drawn_dashed_in_orange_and_named(qtbot):
    t = np.logspace(-3, 1, 80)
    plot = _plot(qtbot, (306, 180), "Signature", "t (log)", "S_t")
    plot.set_data(t, np.exp(-t), logx=True, markers=False)

    def orange(image) -> int:
        return sum(
            (c := image.pixelColor(x, y)).red() > 200 and 80 < c.green() < 160 and c.blue() < 80
            for y in range(image.height())
            for x in range(image.width())
        )

    assert orange(plot.grab().toImage()) == 0
    plot.set_second(np.exp(-t) + 0.2, "dashed: all modes")
    assert orange(plot.grab().toImage()) > 50
    legend = plot.ax.get_legend()
    assert [text.get_text() for text in legend.get_texts()] == ["dashed: all modes"]
    # a log axis is labelled at powers of ten only (the minor ticks' labels would overlap)
    shown = _shown_ticks(plot.ax.xaxis, plot.ax.get_xlim())
    assert [v for v, _ in shown] == pytest.approx([1e-3, 1e-2, 1e-1, 1e0, 1e1])
    narrow = _plot(qtbot, (306, 180), x=np.geomspace(0.15, 5.8, 50), y=np.ones(50), logx=True)
    assert [v for v, _ in _shown_ticks(narrow.ax.xaxis, narrow.ax.get_xlim())] == [1.0]
    assert not any(label.get_text() for label in narrow.ax.xaxis.get_minorticklabels())
    plot.set_second(None)
    assert orange(plot.grab().toImage()) == 0
