"""Small widget helpers shared by the panels."""

from __future__ import annotations

from contextlib import contextmanager

from qtpy import QtWidgets


def combo() -> QtWidgets.QComboBox:
    """A combo box as wide as 14 characters, not as its longest item (a dock has a
    340-pixel limit; a wider combo would cut off its right edge)."""
    box = QtWidgets.QComboBox()
    box.setSizeAdjustPolicy(
        QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
    )
    box.setMinimumContentsLength(14)
    return box


def select_data(box: QtWidgets.QComboBox, data) -> None:
    index = box.findData(data)
    if index >= 0 and index != box.currentIndex():
        box.setCurrentIndex(index)


@contextmanager
def quiet(*widgets):
    """Update widgets from the state without their signals setting the state back."""
    previous = [w.blockSignals(True) for w in widgets]
    try:
        yield
    finally:
        for w, was in zip(widgets, previous, strict=True):
            w.blockSignals(was)
