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
def spot_path():
    return ASSETS / "spot.obj"
