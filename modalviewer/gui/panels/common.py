"""Small widget helpers shared by the panels."""

from __future__ import annotations

from contextlib import contextmanager

from qtpy import QtCore, QtWidgets


def combo() -> QtWidgets.QComboBox:
    """A combo box as wide as 14 characters, not as its longest item (a dock has a
    340-pixel limit; a wider combo would cut off its right edge), its current item's
    whole text in its tooltip."""
    policy = QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
    box = QtWidgets.QComboBox(sizeAdjustPolicy=policy, minimumContentsLength=14)
    # the box shows the start of a long item ("Discrete Shells, normal v..."); the
    # tooltip names it whole, above what the box is for (see describe)
    box.currentTextChanged.connect(lambda _text: _refresh_tooltip(box))
    return box


def add_items(box: QtWidgets.QComboBox, items) -> QtWidgets.QComboBox:
    """``box`` with the items (label, data) or (label, data, tooltip) added."""
    for label, data, *tip in items:
        box.addItem(label, data)
        if tip:
            box.setItemData(box.count() - 1, tip[0], QtCore.Qt.ItemDataRole.ToolTipRole)
    return box


def describe(box: QtWidgets.QComboBox, text: str) -> None:
    """What ``box`` is for, shown in its tooltip below its current item's whole text."""
    box.setProperty("purpose", text)
    _refresh_tooltip(box)


def _refresh_tooltip(box: QtWidgets.QComboBox) -> None:
    purpose = box.property("purpose") or ""
    parts = [part for part in (box.currentText(), purpose) if part]
    box.setToolTip("\n".join(parts))


class WrappingLabel(QtWidgets.QLabel):
    """A word-wrapped label as high as its text at its width (minimum and hinted height):
    layouts in a scroll area size a wrapped label once, so a plain one whose text grows
    from two lines to six stays two lines high, cut at top and bottom."""

    def __init__(self, text: str = "", parent=None):
        super().__init__(text, parent)
        self.setWordWrap(True)

    def setText(self, text: str) -> None:  # noqa: N802 (Qt override)
        super().setText(text)
        self._fit()

    def resizeEvent(self, event) -> None:  # noqa: N802
        super().resizeEvent(event)
        self._fit()

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 (Qt override)
        # QLabel's own hint wraps a short text at a fraction of 80 characters, two lines
        # high, and a form layout gives the label that height: one line centred in two
        hint = super().sizeHint()
        hint.setHeight(self.minimumHeight() or hint.height())
        return hint

    def _fit(self) -> None:
        # QLabel's heightForWidth is never below the minimum height, so it is measured
        # without one: a text that shrinks (three lines back to one) gets a shorter label,
        # not its line centred in the height of the longer text
        kept = self.minimumHeight()
        self.setMinimumHeight(0)
        needed = self.heightForWidth(max(self.width(), 1))
        self.setMinimumHeight(needed if needed > 0 else kept)


def slider(low: int, high: int, tip: str = "") -> QtWidgets.QSlider:
    horizontal = QtCore.Qt.Orientation.Horizontal
    return QtWidgets.QSlider(horizontal, minimum=low, maximum=high, toolTip=tip)


def spin_box(low, high, value=None, tip: str = "", **props) -> QtWidgets.QSpinBox:
    box = QtWidgets.QSpinBox(minimum=low, maximum=high, toolTip=tip, **props)
    if value is not None:
        box.setValue(int(value))
    return box


def row(*items) -> QtWidgets.QHBoxLayout:
    """A row of widgets; a number is a stretch, (widget, n) a widget stretched n, a
    string a label."""
    layout = QtWidgets.QHBoxLayout()
    for item in items:
        if isinstance(item, int):
            layout.addStretch(item)
        elif isinstance(item, str):
            layout.addWidget(QtWidgets.QLabel(item))
        elif isinstance(item, tuple):
            layout.addWidget(*item)
        else:
            layout.addWidget(item)
    return layout


def follow(state, slot, *names: str) -> None:
    """Call ``slot`` on each of ``state``'s events ``names`` ("display", "mesh", ...)."""
    for name in names:
        getattr(state.events, name).connect(slot)


def bind(widget, setter) -> None:
    """Call ``setter(value)`` with ``widget``'s new value (a combo box's item data, a
    check box's or checkable button's state, a spin box's or slider's number) when the
    user changes it."""
    if isinstance(widget, QtWidgets.QComboBox):
        widget.currentIndexChanged.connect(lambda _index: setter(widget.currentData()))
    elif isinstance(widget, QtWidgets.QAbstractButton):
        widget.toggled.connect(setter)
    else:
        widget.valueChanged.connect(setter)


def show_values(pairs) -> None:
    """Set each widget of ``pairs`` (widget, value) to its value, its signals blocked
    (the state it shows is not set back)."""
    pairs = list(pairs)
    with quiet(*(widget for widget, _ in pairs)):
        for widget, value in pairs:
            if isinstance(widget, QtWidgets.QComboBox):
                select_data(widget, value)
            elif isinstance(widget, QtWidgets.QAbstractButton):
                widget.setChecked(value)
            else:
                widget.setValue(value)


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
