import os
from pathlib import Path

import pytest

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture(autouse=True)
def _isolated(tmp_path, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_NO_DIALOGS", "1")
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("MODALVIEWER_SETTINGS", str(tmp_path / "settings.ini"))
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        monkeypatch.setenv("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


@pytest.fixture
def window(qtbot):
    from modalviewer.gui import MainWindow

    win = MainWindow()
    win.resize(1280, 800)
    qtbot.addWidget(win)
    win.show()
    qtbot.waitExposed(win)
    yield win
    win.close()


@pytest.fixture
def answer_next_dialog(qtbot, monkeypatch):
    """``answer(delay_ms)`` lets the next modal dialog really open (no
    MODALVIEWER_NO_DIALOGS), presses Enter on it (its default button) after ``delay_ms``
    and returns the dict that then holds its ``title``, ``default`` button and ``text``."""
    from qtpy import QtCore, QtWidgets

    monkeypatch.delenv("MODALVIEWER_NO_DIALOGS")

    def answer(delay_ms: int = 200) -> dict:
        asked = {}

        def press_enter():
            # the question may open later than delay_ms (a file is still being read, in a
            # loaded machine's time): look again until a message box is up
            box = QtWidgets.QApplication.activeModalWidget()
            if not isinstance(box, QtWidgets.QMessageBox):
                QtCore.QTimer.singleShot(50, press_enter)
                return
            asked["title"] = box.windowTitle()
            asked["default"] = box.defaultButton().text().replace("&", "")
            asked["text"] = box.text()
            qtbot.keyClick(box, QtCore.Qt.Key.Key_Return)

        QtCore.QTimer.singleShot(delay_ms, press_enter)
        return asked

    return answer


@pytest.fixture
def spot_path():
    return ASSETS / "spot.obj"


@pytest.fixture
def display_position():
    """``display_position(scene, vertex)``: (x, y, depth) display coordinates of a mesh
    vertex as ``scene``'s renderer draws it (VTK origin: bottom left)."""

    def position(scene, vertex: int) -> tuple[float, float, float]:
        renderer = scene.plotter.renderer
        renderer.SetWorldPoint(*scene.surface.points[vertex], 1.0)
        renderer.WorldToDisplay()
        return renderer.GetDisplayPoint()

    return position
