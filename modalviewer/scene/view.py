"""The 3D picture of the viewer state, the same code in the window and off screen, so an
export from a script shows what the window shows.  Only the plotter's thread runs it."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..viewer import wording
from ..viewer.camera import Camera
from ..viewer.derived import Field
from ..viewer.state import ViewerState
from .isolines import line_polydata
from .mesh_scene import MeshScene, add_actor


def draw_field(scene: MeshScene, field: Field | None) -> None:
    """Colour ``scene``'s surface by ``field`` (None: the grey surface), displaced and with
    the ghost as it says: the one way a field becomes a picture, in every view."""
    scene.set_displacement_scale(0.0)
    if field is None or field.colormap == "plain":
        scene.show_plain()
    elif field.colormap == "threshold":
        scene.show_threshold(field.values, field.threshold, name=field.title)
    else:
        scene.show_field(
            field.values,
            field.colormap,
            clim=field.clim,
            isolines=field.isolines,
            displacement=field.displacement,
            name=field.title,
            clipped=field.clipped,
            scale=field.scale,
        )
    deformation = field.deformation if field is not None else 0.0
    if deformation:
        scene.set_displacement_scale(deformation)
    scene.set_ghost(bool(field is not None and field.ghost), deformation)


def label_field(scene: MeshScene, field: Field | None) -> None:
    """The colour bar of ``field`` drawn without a legend (the compare views); a threshold
    map's is two swatches ("<title> < threshold", "the rest")."""
    if field is None or field.colormap == "plain":
        scene.set_colorbar(None)
    elif field.colormap == "threshold":
        similar = f"{field.title} < {field.threshold:.3g}"
        if field.share_similar is not None:
            similar += f" ({100 * field.share_similar:.1f} %)"
        scene.set_colorbar(field.title, labels=[similar, "the rest"])
    else:
        scene.set_colorbar(field.title, clim=field.clim)


class StateScene:
    """Keeps a :class:`MeshScene` on ``plotter`` in step with ``state``, calling
    ``request_render()`` after every change and ``on_animation`` when the state starts or
    stops the animation (the window runs its clock)."""

    def __init__(self, state: ViewerState, plotter, request_render=None, on_animation=None):
        self.state = state
        self.plotter = plotter
        self.request_render = request_render or (lambda: None)
        self.on_animation = on_animation
        self.scene: MeshScene | None = None
        self.field: Field | None = None
        self.outline_actor = None
        self._drawn = None  # (display, style, pick, spectra ids) the picture was drawn for
        for event, slot in self._connections():
            event.connect(slot)

    def _connections(self) -> tuple:
        events = self.state.events
        return (
            (events.mesh, self._on_mesh),
            (events.display, self.redraw),
            (events.style, self.redraw),
            (events.pick, self._on_pick),
            (events.animation, self._on_animation),
            (events.camera, self._apply_camera),
            (events.up_axis, self._on_up_axis),
        )

    # -------------------------------------------------------------- mesh
    def sync(self) -> None:
        """Draw the state as it is now (a scene attached to a state already in use)."""
        self._on_mesh()
        self.redraw()
        self._on_pick()
        self._apply_camera()

    def close(self) -> None:
        for event, slot in self._connections():
            event.disconnect(slot)
        if self.scene is not None:
            self.scene.remove()
            self.scene = None

    def _on_mesh(self) -> None:
        if self.on_animation is not None:
            self.on_animation(False)
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
            self.scene.up_axis = self.state.derived.up_axis()
            self.reset_camera()
        self._update_colorbar()
        self.request_render()

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
            state.style.log_signature,
        )

    def redraw(self) -> None:
        """Draw what the state displays (a threshold move only recolours)."""
        if self.scene is None:
            return
        signature = self._signature()
        if self.scene.style != self.state.style.render:
            self.scene.set_style(self.state.style.render)
        # a threshold map drawn for this display (all of it but the threshold): recoloured
        if (
            self._drawn == signature
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
        self.request_render()

    def _draw_field(self) -> None:
        field = self.state.derived.field()
        self.field = field
        draw_field(self.scene, field)
        if self.state.animation.playing:
            self.scene.set_displacement_scale(0.0)  # the next frame moves it
        self._show_outline_if_due()
        self.scene.show_marker(self.state.picked)  # on the surface as drawn

    def _show_outline_if_due(self) -> None:
        """The outline stays at the rest shape: shown with it, or with a deformed one's ghost."""
        if self.outline_actor is None:
            return
        field = self.field
        deformed = field is not None and field.deformation > 0
        still = not self.state.animation.playing
        self.outline_actor.SetVisibility(
            (still and not deformed) or (field is not None and field.ghost)
        )

    def _show_outline(self, mesh) -> None:
        """The mesh's boundary as thin grey lines: in the paper style a surface facing
        the viewer is as white as the background, so an open mesh (a plate) seen from
        the front had no visible edge.  Hidden while a mode vibrates or is drawn deformed
        (it would stay put), unless the rest shape's ghost is shown."""
        self.plotter.remove_actor("outline", render=False)
        self.outline_actor = None
        boundary = mesh.edges[mesh.edge_face_counts == 1]
        if len(boundary) == 0:
            return
        lines = line_polydata(np.asarray(mesh.vertices, dtype=np.float64)[boundary], None)
        self.outline_actor = add_actor(
            self.plotter, lines, "outline", color=(0.45, 0.45, 0.45), line_width=1.5
        )

    def _on_pick(self) -> None:
        if self.scene is not None:
            self.scene.show_marker(self.state.picked)
            self.request_render()

    # ------------------------------------------------------------ legend
    def _update_colorbar(self) -> None:
        """Legend and colour bar as the style asks; a threshold map's follows the threshold."""
        scene, field = self.scene, self.field
        if scene is None:
            return
        if field is None or field.colormap == "plain" or not self.state.style.colorbar:
            field = None
        scene.set_legend(field.legend if field is not None else None)
        if field is None or field.colormap != "threshold":
            label_field(scene, field)
            return
        from ..core.operators import DISTANCE_KINDS

        dist = self.state.derived.distance_map()
        thr = self.state.derived.threshold_value(dist)
        share = 100.0 * self.state.derived.surface_share(dist, thr)
        kind = DISTANCE_KINDS[self.state.display.distance_kind].lower()
        similar = f"{kind} < {thr:.3g} ({share:.1f} %)" + wording.display_mark(self.state)
        scene.set_colorbar(field.title, labels=[similar, "the rest"])

    # ------------------------------------------------------------ camera
    def reset_camera(self, preset: str = "canonical") -> None:
        """The mesh's canonical view (R), or camera ``preset`` ("+x" ... "-z", "isometric")."""
        if self.scene is not None:
            self.scene.reset_camera(preset)
            self.request_render()

    def _on_up_axis(self) -> None:
        if self.scene is not None:
            self.scene.up_axis = self.state.derived.up_axis()
            self.reset_camera()

    def _apply_camera(self) -> None:
        camera = self.state.camera
        if camera is None or self.scene is None:
            return
        self.scene.set_camera(Camera.from_dict(camera), fit=bool(camera.get("fit", False)))
        self.request_render()

    def current_camera(self) -> dict:
        cam = self.plotter.camera
        return Camera(cam.position, cam.focal_point, cam.up).as_dict()

    # --------------------------------------------------------- animation
    def _on_animation(self) -> None:
        playing = self.state.animation.playing and self.scene is not None
        self._show_outline_if_due()
        if not playing and self.scene is not None:
            # still: the deformed shape at the amplitude (or the rest shape)
            deformation = self.state.derived.deformation()
            if self.field is not None:
                self.field.deformation = deformation
            self.scene.set_displacement_scale(deformation)
            self.scene.set_color_factor(1.0)
            self.scene.show_marker(self.state.picked)
            self.request_render()
        if self.on_animation is not None:
            self.on_animation(playing)

    def animation_frame(self, phase: float) -> float:
        """Move the surface and scale a signed mode's colours to ``sin(phase)`` of the
        amplitude; returns the time this took in s."""
        started = time.perf_counter()
        amplitude = self.state.derived.amplitude_length()
        self.scene.set_displacement_scale(amplitude * np.sin(phase))
        self.scene.set_color_factor(float(np.sin(phase)))
        self.request_render()
        return time.perf_counter() - started
