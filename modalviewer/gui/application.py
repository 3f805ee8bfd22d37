"""The QApplication a window needs, made where a script or notebook runs one."""

from __future__ import annotations

import os
import sys

from ..scene.platform import has_display, prepare_offscreen


def ensure_application():
    """The running QApplication, or a new one: without a display it runs on Qt's
    off-screen platform (set before Qt starts; a ``QT_QPA_PLATFORM`` already set wins)
    and VTK renders with EGL, so ``MainWindow()`` works in a script, a notebook kernel
    or a test without a display instead of aborting the process."""
    from qtpy import QtWidgets

    app = QtWidgets.QApplication.instance()
    if app is not None:
        return app
    if not has_display():
        os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    prepare_offscreen()
    _quiet_offscreen_notices()
    app = QtWidgets.QApplication(sys.argv[:1])
    app.setApplicationName("modalviewer")
    app.setOrganizationName("modalviewer")
    return app


OFFSCREEN_NOTICES = ("This plugin does not support propagateSizeHints()",)
"""Messages Qt's off-screen platform prints for every window it shows: they say nothing
about the picture, and a ``--screenshot`` run printed them among its own lines."""


def _quiet_offscreen_notices() -> None:
    """Drop :data:`OFFSCREEN_NOTICES` from Qt's messages; every other message goes to
    stderr as Qt prints it."""
    from qtpy import QtCore

    def handler(kind, context, message: str) -> None:
        if message in OFFSCREEN_NOTICES:
            return
        sys.stderr.write(message + "\n")

    QtCore.qInstallMessageHandler(handler)
