"""Keys of the secondary windows (compare, shape pair), one table per window, serving
two routes: on a desktop the focused 3D view takes key presses before keyPressEvent, so
window shortcuts come first; off screen shortcuts do not fire and keyPressEvent handles
the keys.
"""

from __future__ import annotations

from collections.abc import Callable

from qtpy import QtCore, QtGui


def install_keys(window, keys: list[tuple[str, Callable[[], None]]]) -> dict:
    """Window shortcuts for ``keys`` (key sequence text, slot); returns the table for
    :func:`dispatch_key`."""
    table = {QtGui.QKeySequence(key).toString(): slot for key, slot in keys}
    context = QtCore.Qt.ShortcutContext.WidgetWithChildrenShortcut
    for key, slot in table.items():
        shortcut = QtGui.QShortcut(QtGui.QKeySequence(key), window)
        shortcut.setContext(context)
        shortcut.activated.connect(slot)
    return table


def dispatch_key(table: dict, event) -> bool:
    """Run the slot of ``event``'s key; False if the table has none."""
    slot = table.get(QtGui.QKeySequence(event.keyCombination()).toString())
    if slot is None:
        return False
    slot()
    return True
