"""The viewer's picture without a window (EGL where there is no display, no Qt)."""

from __future__ import annotations

from .platform import prepare_offscreen
from .view import StateScene

DEFAULT_SIZE = (1024, 768)
"""Pixels of an off-screen picture unless a size is given."""


def offscreen_plotter(size=DEFAULT_SIZE):
    """A white-background pyvista plotter rendering off screen, ready to render."""
    prepare_offscreen()
    import pyvista as pv

    from .framing import fit_smaller_side

    plotter = pv.Plotter(off_screen=True, notebook=False, window_size=[int(size[0]), int(size[1])])
    plotter.set_background("white")
    fit_smaller_side(plotter.renderer)
    return plotter


class OffscreenRenderer:
    """Draws ``state`` off screen at ``size`` pixels; follows the state as a window does
    (a new mesh gets the canonical first view)."""

    def __init__(self, state, size=DEFAULT_SIZE):
        self.state = state
        self.plotter = offscreen_plotter(size)
        self.drawing = StateScene(state, self.plotter)
        if state.mesh is not None:  # the state's present, as a window opened now shows it
            self.drawing.sync()

    @property
    def scene(self):
        return self.drawing.scene

    @property
    def size(self) -> tuple[int, int]:
        return tuple(int(x) for x in self.plotter.window_size)

    def resize(self, size) -> None:
        """Change the picture's size; the camera is fitted again if the mesh was in view."""
        size = (int(size[0]), int(size[1]))
        if size != self.size:
            self.plotter.window_size = list(size)
            self.drawing.reset_camera()

    def set_camera(self, camera: dict | None) -> None:
        """Look from ``camera`` as plain data (a window's); None keeps the camera."""
        if camera is None or self.scene is None:
            return
        from ..viewer.camera import Camera

        self.scene.set_camera(Camera.from_dict(camera), fit=False)

    def frame(
        self, reach: float | None = None, both: bool = False, colorbar: bool | None = None
    ) -> None:
        """Fit the camera, keeping its direction, to the shape clear of the legend and colour
        bar: :meth:`.MeshScene.motion_points` at ``reach`` (default: as drawn)."""
        from .framing import fit_clear_of_overlay

        scene = self.scene
        if scene is None:
            return
        if reach is None:
            field = self.drawing.field
            reach = field.deformation if field is not None else 0.0
        fit_clear_of_overlay(
            self.plotter.renderer,
            scene.motion_points(reach, both),
            self.size,
            scene.overlay(colorbar=colorbar),
            scene.overlay_scale,
        )

    def image(
        self,
        scale: int = 1,
        transparent: bool = False,
        colorbar: bool | None = None,
        marker: bool = True,
    ):
        """The picture as an (h, w, 3 or 4) uint8 array, legend and colour bar drawn on."""
        from .export import grab

        return grab(self.plotter, self.scene, scale, transparent, colorbar=colorbar, marker=marker)

    def close(self) -> None:
        self.drawing.close()
        self.plotter.close()
