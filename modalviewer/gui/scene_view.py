"""The 3D view of the viewer state: draws ``state.derived.field()``, the pick, the animation.

It observes :class:`~modalviewer.viewer.state.ViewerState` and keeps nothing the state
does not say, except VTK objects and the animation clock.  Only the GUI thread runs it.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
from qtpy import QtCore

from ..viewer import wording
from ..viewer.derived import Field
from ..viewer.state import ViewerState
from .scene import MeshScene


class SceneView(QtCore.QObject):
    """Keeps a :class:`MeshScene` on ``viewport`` in step with ``state``."""

    def __init__(self, state: ViewerState, viewport, parent=None):
        super().__init__(parent)
        self.state = state
        self.viewport = viewport
        self.plotter = viewport.plotter
        self.scene: MeshScene | None = None
        self.field: Field | None = None
        self._drawn = None  # (display, style, pick, spectra ids) the picture was drawn for
        self._phase = 0.0
        self._last_tick: float | None = None
        self.frame_times: list[float] = []
        self.timer = QtCore.QTimer(self)
        self.timer.setInterval(16)
        self.timer.timeout.connect(self._animate_step)
        state.events.mesh.connect(self._on_mesh)
        state.events.display.connect(self.redraw)
        state.events.style.connect(self.redraw)
        state.events.pick.connect(self._on_pick)
        state.events.animation.connect(self._on_animation)
        state.events.camera.connect(self._apply_camera)

    # -------------------------------------------------------------- mesh
    def _on_mesh(self) -> None:
        self.timer.stop()
        if self.scene is not None:
            self.scene.remove()
            self.scene = None
        self.field = None
        self._drawn = None
        mesh = self.state.mesh
        if mesh is not None:
            self.scene = MeshScene(
                self.plotter, mesh, self.state.derived.normals, style=self.state.style.render
            )
            self._show_outline(mesh)
            self.reset_camera()
        self._update_colorbar()
        self.viewport.request_render()

    # ------------------------------------------------------------- field
    def _signature(self):
        state = self.state
        d = state.display
        spec = state.spectrum(state.display_operator())
        return (
            replace(d, threshold=0.0),
            (state.style.isolines, state.style.shell_coloring, state.style.render),
            state.picked if d.kind == "distance" else None,
            id(spec),
            state.t_range,
        )

    def redraw(self) -> None:
        """Draw what the state displays (a threshold move only recolours)."""
        if self.scene is None:
            return
        signature = self._signature()
        d = self.state.display
        if self.scene.style != self.state.style.render:
            self.scene.set_style(self.state.style.render)
        if (
            self._drawn == signature
            and d.kind == "distance"
            and d.distance_display == "threshold"
            and self.field is not None
            and self.field.colormap == "threshold"
            and self.state.derived.distance_map() is not None
        ):
            thr = self.state.derived.threshold_value()
            self.scene.set_threshold(thr)
            self.field.threshold = thr
            self.field.legend = wording.legend(self.state)
        else:
            self._draw_field()
            self._drawn = signature
        self._update_colorbar()
        self.viewport.request_render()

    def _draw_field(self) -> None:
        field = self.state.derived.field()
        self.field = field
        scene = self.scene
        scene.set_displacement_scale(0.0)
        if field is None or field.colormap == "plain":
            scene.show_plain()
            return
        if field.colormap == "threshold":
            scene.show_threshold(field.values, field.threshold, name=field.title)
            return
        scene.show_field(
            field.values,
            field.colormap,
            clim=field.clim,
            isolines=field.isolines,
            displacement=field.displacement,
            name=field.title,
        )
        if self.state.animation.playing:
            self._phase = 0.0

    def _show_outline(self, mesh) -> None:
        """The mesh's boundary as thin grey lines: in the paper style a surface facing
        the viewer is as white as the background, so an open mesh (a plate) seen from
        the front had no visible edge.  Hidden while a mode vibrates (it would stay put)."""
        import pyvista as pv

        self.plotter.remove_actor("outline", render=False)
        self.outline_actor = None
        boundary = mesh.edges[mesh.edge_face_counts == 1]
        if len(boundary) == 0:
            return
        cells = np.column_stack([np.full(len(boundary), 2), boundary]).ravel()
        lines = pv.PolyData(np.asarray(mesh.vertices, dtype=np.float64), lines=cells)
        self.outline_actor = self.plotter.add_mesh(
            lines,
            color=(0.45, 0.45, 0.45),
            line_width=1.5,
            name="outline",
            render=False,
            reset_camera=False,
            show_scalar_bar=False,
        )

    def _on_pick(self) -> None:
        if self.scene is not None:
            self.scene.show_marker(self.state.picked)
            self.viewport.request_render()

    # ------------------------------------------------------------ legend
    def _update_colorbar(self) -> None:
        """Legend and colour bar as the style asks (both on or both off), titles in
        words; a threshold map gets a two-swatch legend that follows the threshold."""
        scene, field = self.scene, self.field
        if scene is None:
            return
        if field is None or field.colormap == "plain" or not self.state.style.colorbar:
            scene.set_legend(None)
            scene.set_colorbar(None)
            return
        scene.set_legend(field.legend)
        if field.colormap == "threshold":
            d = self.state.display
            dist = self.state.derived.distance_map()
            thr = self.state.derived.threshold_value(dist)
            share = 100.0 * self.state.derived.surface_share(dist, thr)
            from ..core.operators import DISTANCE_KINDS

            similar = f"{DISTANCE_KINDS[d.distance_kind].lower()} < {thr:.3g} ({share:.1f} %)"
            similar += wording.display_mark(self.state)
            scene.set_colorbar(field.title, labels=[similar, "the rest"])
        else:
            scene.set_colorbar(field.title, clim=field.clim)

    # ------------------------------------------------------------ camera
    def reset_camera(self) -> None:
        """The mesh's canonical view, fitted to the window (R)."""
        if self.scene is not None:
            self.scene.reset_camera()
            self.viewport.request_render()

    def camera_preset(self, name: str) -> None:
        """View from a side ("+x" ... "-z"), "isometric" or "canonical"."""
        if self.scene is not None:
            self.scene.apply_camera_preset(name)
            self.viewport.request_render()

    def _apply_camera(self) -> None:
        camera = self.state.camera
        if camera is None or self.scene is None:
            return
        from ..viewer.camera import Camera

        self.scene.set_camera(
            Camera(
                tuple(camera["position"]), tuple(camera["focal_point"]), tuple(camera["view_up"])
            ),
            fit=bool(camera.get("fit", False)),
        )
        self.viewport.request_render()

    def current_camera(self) -> dict:
        """The camera as plain data (for sessions)."""
        cam = self.plotter.camera
        return {
            "position": [float(x) for x in cam.position],
            "focal_point": [float(x) for x in cam.focal_point],
            "view_up": [float(x) for x in cam.up],
        }

    # --------------------------------------------------------- animation
    def _on_animation(self) -> None:
        outline = getattr(self, "outline_actor", None)
        if outline is not None:
            outline.SetVisibility(not self.state.animation.playing)
        if self.state.animation.playing and self.scene is not None:
            self._last_tick = time.perf_counter()
            self.timer.start()
        else:
            self.timer.stop()
            if self.scene is not None:
                self.scene.set_displacement_scale(0.0)
                self.viewport.request_render()

    def animation_frame(self, phase: float) -> float:
        """Move the surface to ``phase`` (radians); returns the app's time in s."""
        started = time.perf_counter()
        amplitude = (
            self.state.animation.amplitude / 100.0 * 0.25 * self.state.mesh.bounding_box_diagonal
        )
        self.scene.set_displacement_scale(amplitude * np.sin(phase))
        self.viewport.request_render()
        return time.perf_counter() - started

    def _animate_step(self) -> None:
        if self.scene is None or not self.state.animation.playing:
            self.timer.stop()
            return
        now = time.perf_counter()
        dt = now - (self._last_tick or now)
        self._last_tick = now
        self._phase += dt * self.state.animation.speed / 10.0
        self.frame_times.append(self.animation_frame(self._phase))
        del self.frame_times[:-200]
