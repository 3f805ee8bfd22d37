"""The window's 3D view of the viewer state: :class:`~modalviewer.scene.view.StateScene`
on the window's viewport, plus the animation clock (a QTimer)."""

from __future__ import annotations

import time

from qtpy import QtCore

from ..scene.view import StateScene
from ..viewer.state import ViewerState


class SceneView(QtCore.QObject):
    """Draws ``state`` on ``viewport`` (through a :class:`StateScene`) and animates it."""

    def __init__(self, state: ViewerState, viewport, parent=None):
        super().__init__(parent)
        self.state = state
        self.plotter = viewport.plotter  # plotter and scene: what the viewer's pictures use
        self._phase = 0.0
        self._last_tick: float | None = None
        self.frame_times: list[float] = []
        self.timer = QtCore.QTimer(self, interval=16)
        self.timer.timeout.connect(self._animate_step)
        self.drawing = StateScene(
            state, viewport.plotter, viewport.request_render, on_animation=self._on_animation
        )
        state.events.display.connect(lambda: setattr(self, "_phase", 0.0))  # from rest

    @property
    def scene(self):
        return self.drawing.scene

    def _on_animation(self, playing: bool) -> None:
        if playing:
            self._last_tick = time.perf_counter()
            self.timer.start()
        else:
            self.timer.stop()

    def _animate_step(self) -> None:
        if self.scene is None or not self.state.animation.playing:
            self.timer.stop()
            return
        now = time.perf_counter()
        dt = now - (self._last_tick or now)
        self._last_tick = now
        self._phase += dt * self.state.animation.speed / 10.0
        self.frame_times.append(self.drawing.animation_frame(self._phase))
        del self.frame_times[:-200]
