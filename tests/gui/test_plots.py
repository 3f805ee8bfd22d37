"""The spectrum plot: zero modes read 0, tick labels along the bottom."""

import numpy as np
import pytest

from modalviewer.gui.plots import TITLE_MARGIN, LinePlot, axis_label, nice_ticks

pytestmark = pytest.mark.gui


def test_axis_labels_of_zero_modes_and_round_ticks():
    assert axis_label(3.99e-14, 52.0) == "0"
    assert axis_label(-1.6e-07, 52.0) == "0"
    assert axis_label(-1.6e-07, 1e-3) == "-1.6e-07"  # not round-off at that scale
    assert axis_label(52.123, 52.123) == "52.1"
    assert list(nice_ticks(0, 99, 5)) == [0, 20, 40, 60, 80]
    assert list(nice_ticks(0.0, 1.0, 6)) == pytest.approx([0, 0.2, 0.4, 0.6, 0.8, 1.0])


def test_spectrum_plot_shows_zero_and_tick_labels(qtbot):
    plot = LinePlot("Spectrum", "mode index", "eigenvalue")
    qtbot.addWidget(plot)
    plot.resize(360, 180)
    lam = np.array([3.99e-14, -1.6e-07, 2.0, 5.0, 9.0, 14.0, 20.0, 27.0, 35.0, 44.0])
    plot.set_data(np.arange(10), np.where(lam < 1e-6, 0.0, lam))  # zero modes as 0
    ticks = plot.x_ticks()
    assert [v for v, _ in ticks] == [0, 2, 4, 6, 8]
    xs = [x for _, x in ticks]
    assert xs == sorted(xs) and xs[0] >= 40 and xs[-1] <= 360
    image = plot.grab().toImage()
    rect = plot._transform()[0]
    # dark text pixels in the band just below the frame (the tick labels)
    dark = 0
    for y in range(rect.bottom() + 4, rect.bottom() + 17):
        for x in range(rect.left(), rect.right()):
            c = image.pixelColor(x, y)
            dark += c.red() < 100 and c.green() < 100 and c.blue() < 100
    assert dark > 30, dark


def test_a_title_wider_than_the_plot_wraps_whole(qtbot):
    """Seen under Xvfb: "Spectrum (coarse-to-fine): Discrete Shells (3D vibrations" lost its
    ")" at the Modes dock's plot width (306 pixels at the default window size)."""
    plot = LinePlot()
    qtbot.addWidget(plot)
    plot.resize(306, 140)
    title = "Spectrum (coarse-to-fine): Discrete Shells (3D vibrations)"
    plot.set_data(np.arange(10), np.arange(10.0) ** 2, title=title)
    metrics = plot.fontMetrics()
    assert metrics.horizontalAdvance(title) > plot.width() - 2 * TITLE_MARGIN
    rect = plot._transform()[0]
    image = plot.grab().toImage()
    dark = [
        (x, y)
        for y in range(rect.top() - 2)
        for x in range(plot.width())
        if image.pixelColor(x, y).lightness() < 100
    ]
    # the title's ink keeps off the right edge, and a second line is drawn above the frame
    assert max(x for x, _ in dark) <= plot.width() - TITLE_MARGIN, max(x for x, _ in dark)
    assert any(y > 14 + 3 for _, y in dark)
    lines = plot.title_lines()
    assert " ".join(lines) == title and len(lines) == 2
    assert all(metrics.horizontalAdvance(line) <= plot.width() - 2 * TITLE_MARGIN for line in lines)
    assert rect.top() >= 20 + metrics.lineSpacing()
    plot.resize(600, 140)  # wide enough: one line, the frame where a one-line title puts it
    assert plot.title_lines() == [title] and plot._transform()[0].top() == 20


def _dark_in(image, xs, ys) -> int:
    return sum(image.pixelColor(x, y).lightness() < 100 for y in ys for x in xs)


def test_the_y_axis_is_named_in_the_left_margin(qtbot):
    """The plot's y label is drawn in the left margin between the value labels at the
    frame's top and bottom: turned to read upwards where it is wider than the margin
    ("eigenvalue"), as it is where it fits ("S_t"); without one the band stays white."""
    lam = np.array([0.0, 2.0, 5.0, 9.0, 14.0, 20.0, 27.0, 35.0, 44.0])
    plots = {}
    for name in ("eigenvalue", ""):
        plot = LinePlot("Spectrum", "mode index", name)
        qtbot.addWidget(plot)
        plot.resize(360, 220)
        plot.set_data(np.arange(lam.size), lam)
        plots[name] = plot
    rect = plots[""]._transform()[0]
    metrics = plots[""].fontMetrics()
    xs = range(0, rect.left() - 2)
    ys = range(rect.top() + metrics.height(), rect.bottom() - metrics.height())
    named, unnamed = (_dark_in(plots[n].grab().toImage(), xs, ys) for n in ("eigenvalue", ""))
    assert unnamed == 0, unnamed
    assert named > 40, named
    # the ink is taller than wide: the word reads upwards
    image = plots["eigenvalue"].grab().toImage()
    ink = [(x, y) for y in ys for x in xs if image.pixelColor(x, y).lightness() < 100]
    width = max(x for x, _ in ink) - min(x for x, _ in ink)
    height = max(y for _, y in ink) - min(y for _, y in ink)
    assert height > 3 * width, (width, height)
    # a name that fits the margin's width stays as it is: wider than tall
    short = LinePlot("Spectrum", "mode index", "S_t")
    qtbot.addWidget(short)
    short.resize(360, 220)
    short.set_data(np.arange(lam.size), lam)
    image = short.grab().toImage()
    ink = [(x, y) for y in ys for x in xs if image.pixelColor(x, y).lightness() < 100]
    assert ink
    width = max(x for x, _ in ink) - min(x for x, _ in ink)
    height = max(y for _, y in ink) - min(y for _, y in ink)
    assert width > height, (width, height)
