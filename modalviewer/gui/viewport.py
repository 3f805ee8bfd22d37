"""The 3D view: pyvistaqt's ``QtInteractor`` where Qt can make an OpenGL context, else an
off-screen pyvista plotter (EGL or OSMesa) whose frames are painted into a plain widget.

Both expose ``plotter``, ``widget``, ``request_render()`` and the ``clicked(x, y)``
signal (VTK display coordinates of a left click that did not drag).  The off-screen
variant runs under ``QT_QPA_PLATFORM=offscreen`` with the same VTK pipeline, so pixels
checked in tests are real renders.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from qtpy import QtCore, QtGui, QtWidgets
from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera
from vtkmodules.vtkRenderingUI import vtkGenericRenderWindowInteractor

from ..scene.framing import fit_smaller_side

CLICK_SLOP = 4  # pixels a press may move and still count as a click


def _is_click(press, x: float, y: float) -> bool:
    """Whether a release at (x, y) after a press at ``press`` (None: none) is a click."""
    return press is not None and max(abs(x - press[0]), abs(y - press[1])) <= CLICK_SLOP


def qt_opengl_available() -> bool:
    """True if Qt can create an OpenGL context on this platform."""
    if QtGui.QGuiApplication.platformName() in ("offscreen", "minimal", "vnc", "linuxfb"):
        return False
    ctx = QtGui.QOpenGLContext()
    return bool(ctx.create())


class OffscreenViewport(QtWidgets.QWidget):
    """A widget showing frames of an off-screen pyvista plotter, navigated as the GPU view:
    VTK's trackball camera (left drag rotates, right drag or wheel zooms, middle drag
    pans); a left click picks."""

    clicked = QtCore.Signal(float, float)
    cameraChanged = QtCore.Signal()

    def __init__(self, parent=None):
        strong = QtCore.Qt.FocusPolicy.StrongFocus
        super().__init__(parent, minimumSize=QtCore.QSize(200, 150), focusPolicy=strong)
        # notebook=False: in a Jupyter kernel pyvista would show through its notebook
        # backend (trame, or an ImportError without it) instead of rendering here
        self.plotter = pv.Plotter(off_screen=True, notebook=False, window_size=(640, 480))
        self.plotter.set_background("white")
        fit_smaller_side(self.plotter.renderer)
        # pyvista skips render() until the first show; show once (off-screen: no window)
        self.plotter.show(auto_close=False, interactive=False)
        self._image: QtGui.QImage | None = None
        self._dirty = True
        self._press_pos = None
        self.render_count = 0
        # VTK's own trackball camera, fed the widget's mouse events; it renders nothing
        # itself (the widget paints on request)
        self._iren = vtkGenericRenderWindowInteractor()
        self._iren.SetEnableRender(False)
        self._iren.SetRenderWindow(self.plotter.ren_win)
        style = vtkInteractorStyleTrackballCamera()
        self._iren.SetInteractorStyle(style)
        for event in ("InteractionEvent", "EndInteractionEvent"):  # drags; the wheel
            style.AddObserver(event, self._on_interaction)

    @property
    def widget(self) -> QtWidgets.QWidget:
        return self

    def request_render(self) -> None:
        self._dirty = True
        self.update()

    def render_now(self) -> np.ndarray:
        """Render synchronously and return the frame (h, w, 3) uint8."""
        w, h = max(self.width(), 16), max(self.height(), 16)
        if tuple(self.plotter.window_size) != (w, h):
            self.plotter.window_size = (w, h)
        self.plotter.render()
        img = np.ascontiguousarray(self.plotter.screenshot(None, return_img=True)[:, :, :3])
        self._image = QtGui.QImage(
            img.data,
            img.shape[1],
            img.shape[0],
            3 * img.shape[1],
            QtGui.QImage.Format.Format_RGB888,
        ).copy()
        self._dirty = False
        self.render_count += 1
        return img

    def paintEvent(self, event):  # noqa: N802 (Qt override)
        if self._dirty or self._image is None:
            self.render_now()
        painter = QtGui.QPainter(self)
        painter.drawImage(0, 0, self._image)
        painter.end()

    def resizeEvent(self, event):  # noqa: N802
        self._dirty = True
        size = event.size()
        self.plotter.window_size = (max(size.width(), 16), max(size.height(), 16))
        super().resizeEvent(event)

    # ---------------------------------------------------------------- mouse
    def _to_vtk(self, event, name: str) -> None:
        """Hand a Qt mouse event to VTK's interactor as the event ``name``."""
        pos = event.position()
        self._iren.SetEventInformationFlipY(int(pos.x()), int(pos.y()))
        self._iren.InvokeEvent(name)

    def mousePressEvent(self, event):  # noqa: N802
        self._press_pos = (event.position().x(), event.position().y())
        self._to_vtk(event, event.button().name + "PressEvent")  # e.g. LeftButtonPressEvent

    def mouseMoveEvent(self, event):  # noqa: N802
        self._to_vtk(event, "MouseMoveEvent")

    def mouseReleaseEvent(self, event):  # noqa: N802
        pos = event.position()
        left = event.button() == QtCore.Qt.MouseButton.LeftButton
        if left and _is_click(self._press_pos, pos.x(), pos.y()):
            self.clicked.emit(pos.x(), self.height() - 1 - pos.y())
        self._press_pos = None
        self._to_vtk(event, event.button().name + "ReleaseEvent")

    def wheelEvent(self, event):  # noqa: N802
        forward = event.angleDelta().y() > 0
        self._to_vtk(event, "MouseWheelForwardEvent" if forward else "MouseWheelBackwardEvent")

    def _on_interaction(self, *_args) -> None:
        self.request_render()
        self.cameraChanged.emit()

    def close_plotter(self) -> None:
        self.plotter.close()


class InteractorViewport(QtCore.QObject):
    """pyvistaqt's QtInteractor (GPU, VTK's own trackball) with click detection."""

    clicked = QtCore.Signal(float, float)
    cameraChanged = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        from pyvistaqt import QtInteractor

        # No auto_update: pyvistaqt's default re-renders the whole scene five times a
        # second, idle or not (a full core with software OpenGL, taken from the
        # computations); the viewer asks for a render whenever it changes the scene.
        self.plotter = QtInteractor(parent, auto_update=False)
        self.plotter.set_background("white")
        fit_smaller_side(self.plotter.renderer)
        self._press = None
        iren = self.plotter.iren
        iren.add_observer("LeftButtonPressEvent", self._on_press)
        iren.add_observer("LeftButtonReleaseEvent", self._on_release)
        iren.add_observer("InteractionEvent", lambda *_: self.cameraChanged.emit())
        self.render_count = 0

    @property
    def widget(self) -> QtWidgets.QWidget:
        return self.plotter.interactor

    def _event_position(self):
        # the observer's caller may be the interaction style; ask the interactor itself
        return self.plotter.iren.interactor.GetEventPosition()

    def _on_press(self, _obj, _event):
        self._press = self._event_position()

    def _on_release(self, _obj, _event):
        pos = self._event_position()
        if _is_click(self._press, pos[0], pos[1]):
            self.clicked.emit(float(pos[0]), float(pos[1]))
        self._press = None

    def request_render(self) -> None:
        self.render_count += 1
        self.plotter.update()

    def render_now(self) -> np.ndarray:
        self.plotter.render()
        return np.asarray(self.plotter.screenshot(None, return_img=True))[:, :, :3]

    def close_plotter(self) -> None:
        self.plotter.close()


def make_viewport(parent=None, force_offscreen: bool | None = None):
    """The best viewport this platform supports."""
    offscreen = (not qt_opengl_available()) if force_offscreen is None else force_offscreen
    return OffscreenViewport(parent) if offscreen else InteractorViewport(parent)


def save_views(path, viewports, scenes, scale: int = 1, transparent: bool = False, titles=None):
    """The views of a window side by side in one PNG (written atomically): each
    rendered at ``scale`` with its legend and colour bar drawn on, under its title
    where ``titles`` are given.  Returns the path written."""
    from ..scene.comparison import caption
    from ..scene.export import png_path, save_png, side_by_side

    path = png_path(path)  # checked before rendering
    scale = int(max(1, scale))
    images = grab_views(viewports, scenes, scale, transparent)
    if titles is not None:
        images = [caption(image, title) for image, title in zip(images, titles, strict=True)]
    for viewport in viewports:
        viewport.request_render()
    return save_png(path, side_by_side(images, gap=4 * scale, transparent=transparent))


def grab_views(viewports, scenes, scale: int = 1, transparent: bool = False) -> list:
    """Each view as on screen at ``scale``, its legend and colour bar drawn on."""
    from ..scene.export import grab

    images = []
    for viewport, scene in zip(viewports, scenes, strict=True):
        if hasattr(viewport, "render_now"):
            viewport.render_now()  # an off-screen view sizes its plotter here
        images.append(grab(viewport.plotter, scene, scale, transparent))
    return images
