"""The Viewer's pictures: the field shown, PNG screenshots, animations, mode grids and
comparisons, drawn by :mod:`modalviewer.scene` (loaded on the first picture, so the rest
of the viewer needs no VTK): off screen, or from a window's view
(:meth:`Pictures.attach_picture`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..extras import extra_needed
from .camera import Camera, parse_view, view_camera


class Pictures:
    """The picture methods of :class:`.viewer.Viewer` (which sets ``state``,
    ``_picture`` and ``_renderer``)."""

    def attach_picture(self, source) -> None:
        """Take pictures and camera from ``source`` (a window's view: ``plotter``,
        ``scene``, ``current_camera()``) instead of off screen; None detaches it."""
        self._picture = source
        if source is not None and self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def current_field(self) -> tuple[str, np.ndarray] | None:
        """(name, per-vertex values) of what the surface shows (zeros for the plain
        surface), or None without a mesh."""
        if self.state.mesh is None:
            return None
        field = self.state.derived.field()
        if field is None or field.colormap == "plain":
            return "field", self._input_field(np.zeros(self.state.mesh.n_vertices))
        title = field.title or "field"
        if field.colormap == "threshold":  # the values are the distances: their name only,
            title = title.split(" <")[0]  # not the threshold, which the slider moves
        return title, self._input_field(np.asarray(field.values, dtype=np.float64))

    @extra_needed("Viewer.export_field")
    def export_field(self, path) -> Path:
        """Write the mesh with the field shown as point data (.vtp or .ply)."""
        from ..scene.export import save_field_mesh

        field = self.current_field()
        if field is None:
            raise ValueError("nothing to export: open a mesh first")
        name, values = field
        return save_field_mesh(Path(path), self.mesh, {name: values})

    @extra_needed("the viewer's pictures")
    def renderer(self, size=None):
        """The off-screen renderer, made on first use (``size`` default 1024x768)."""
        from ..scene.offscreen import DEFAULT_SIZE, OffscreenRenderer

        if self._renderer is None:
            self._renderer = OffscreenRenderer(self.state, size or DEFAULT_SIZE)
        elif size is not None:
            self._renderer.resize(size)
        return self._renderer

    @extra_needed("Viewer.export_screenshot")
    def export_screenshot(
        self,
        path,
        scale: int = 1,
        transparent: bool = False,
        colorbar: bool | None = None,
        size=None,
        marker: bool | None = None,
        fit: bool = True,
    ) -> Path:
        """Save the picture as PNG (atomically); returns the path.  With a window and no
        ``size``, its view as on screen; otherwise drawn off screen at ``size`` (default
        1024 x 768, not carried over), with ``fit`` the camera fitted to the whole
        (deformed) shape clear of the legend.  ``scale`` multiplies the pixels;
        ``colorbar`` None and ``marker`` None: as the state says, the marker on distance
        maps only."""
        from ..scene.export import png_path, save_png

        path = png_path(path)  # a wrong name is refused before any drawing
        if colorbar is not None:
            self.state.style.colorbar = colorbar
        return save_png(path, self.image(scale, transparent, size, marker, fit))

    @extra_needed("Viewer.image")
    def image(
        self,
        scale: int = 1,
        transparent: bool = False,
        size=None,
        marker: bool | None = None,
        fit: bool = True,
    ) -> np.ndarray:
        """The picture as an (h, w, 3 or 4) uint8 array (for notebooks); ``size``,
        ``marker`` and ``fit`` as in :meth:`export_screenshot`."""
        marker = self.marker_shown(marker)
        if self._picture is not None and size is None:
            from ..scene.export import grab

            return grab(
                self._picture.plotter, self._picture.scene, scale, transparent, marker=marker
            )
        renderer, temporary = self._offscreen_at(size)
        try:
            if fit:
                renderer.frame()
            return renderer.image(scale, transparent, marker=marker)
        finally:
            if temporary:
                renderer.close()

    def marker_shown(self, marker: bool | None = None) -> bool:
        """``marker`` where given, else True on distance maps only (a mode's picture does
        not depend on the pick)."""
        return bool(marker) if marker is not None else self.state.display.kind == "distance"

    def _offscreen_at(self, size):
        """(renderer at ``size``, whether to close it): this viewer's own, or with a
        window a temporary one from the window's camera."""
        from ..scene.offscreen import DEFAULT_SIZE, OffscreenRenderer

        if self._picture is None:
            return self.renderer(size or DEFAULT_SIZE), False
        w, h = self._picture.plotter.window_size
        renderer = OffscreenRenderer(self.state, size or (int(w), int(h)))
        renderer.set_camera(self.current_camera())
        return renderer, True

    @extra_needed("Viewer.animation_images")
    def animation_images(
        self, frames: int | None = None, fps: float | None = None, size=None, marker=None
    ) -> list[np.ndarray]:
        """One period of the mode shown vibrating, as RGB uint8 frames (``size`` default
        640 x 480; ``frames`` default: one period at ``fps`` at the window's speed), the
        camera fitted to the whole motion.  ValueError when no mode is shown."""
        from ..scene.animation import ANIMATION_SIZE, DEFAULT_FPS, frame_phases, period_frames
        from ..scene.offscreen import OffscreenRenderer

        state = self.state
        d = state.display
        if state.mesh is None or d.kind != "mode" or state.spectrum(d.operator) is None:
            raise ValueError("an animation shows a vibration mode: show a mode first")
        fps = DEFAULT_FPS if fps is None else float(fps)
        if fps <= 0:
            raise ValueError(f"fps must be positive, got {fps:g}")
        n = period_frames(state.animation.speed, fps) if frames is None else int(frames)
        if n < 2:
            raise ValueError(f"an animation needs at least 2 frames, got {n}")
        size = tuple(int(x) for x in (size or ANIMATION_SIZE))
        camera = self.current_camera()
        renderer = OffscreenRenderer(state, size)
        try:
            renderer.set_camera(camera)
            renderer.frame(reach=state.derived.amplitude_length(), both=True)
            images = []
            for phase in frame_phases(n):
                renderer.drawing.animation_frame(phase)
                images.append(renderer.image(marker=bool(marker))[..., :3])
        finally:
            renderer.close()
        return images

    @extra_needed("Viewer.export_animation")
    def export_animation(
        self,
        path,
        frames: int | None = None,
        fps: float | None = None,
        size=None,
        marker: bool | None = None,
    ) -> Path:
        """Write :meth:`animation_images` to a GIF or (with imageio-ffmpeg) an MP4,
        atomically, looping without a jump (``fps`` default 25); returns the path."""
        from ..scene.animation import (
            ANIMATION_SIZE,
            DEFAULT_FPS,
            animation_path,
            write_animation,
        )

        path = animation_path(path, size or ANIMATION_SIZE)  # checked before any drawing
        images = self.animation_images(frames, fps, size, marker)
        return write_animation(path, images, DEFAULT_FPS if fps is None else fps)

    def mode_grid(self, modes, operator: str | None = None, grid=None, size=None) -> np.ndarray:
        """Modes ``modes`` of ``operator`` (default: the one shown) side by side, one
        picture (RGB uint8) of panels of ``size`` (default 400 x 340) in a ``grid``
        (columns, rows; default rows of up to 4): :func:`modalviewer.scene.grid.mode_grid`."""
        from ..scene.grid import GRID_PANEL, mode_grid

        return mode_grid(self, modes, operator, grid, size or GRID_PANEL)

    def export_mode_grid(
        self, path, modes, operator: str | None = None, grid=None, size=None
    ) -> Path:
        """Write :meth:`mode_grid` to a PNG (atomically); returns the path."""
        from ..scene.export import png_path, save_png

        path = png_path(path)
        return save_png(path, self.mode_grid(modes, operator, grid, size))

    def animation_frame(self, phase: float, size=None) -> float:
        """Show the vibration at ``phase`` (radians) until the display changes; returns
        the seconds taken."""
        source = self._picture or self.renderer(size)
        drawing = getattr(source, "drawing", source)
        return drawing.animation_frame(phase)

    def set_view(self, view="canonical", up=None) -> dict | None:
        """Turn the camera to ``view``: "canonical", a preset ("+x" ... "-z", "iso") or
        (azimuth, elevation) in degrees about the up axis (or "AZ,EL"), after choosing
        the ``up`` axis if given.  Returns the camera set, None without a mesh."""
        view = parse_view(view) if isinstance(view, str) else tuple(float(x) for x in view)
        if up is not None:
            self.state.up_axis = up
        mesh = self.state.mesh
        if mesh is None:
            return None
        camera = view_camera(mesh.vertices, mesh.faces, view, up=self.state.derived.up_axis())
        data = {**camera.as_dict(), "fit": True}
        self.state.camera = data
        return data

    def current_camera(self) -> dict | None:
        """The camera of the picture (window or off screen) as plain data."""
        source = self._picture or self._renderer
        if source is None:
            return self.state.camera
        drawing = getattr(source, "drawing", source)
        return drawing.current_camera()

    @extra_needed("Viewer.export_comparison")
    def export_comparison(self, comparison, path, size=None, scale: int = 1) -> Path:
        """Write the views of ``comparison`` (a :meth:`comparison` or its items) side by
        side to a PNG from this viewer's camera, each ``scale`` times ``size``."""
        from ..scene.comparison import VIEW_SIZE, save_comparison

        if not hasattr(comparison, "views"):
            comparison = self.comparison(comparison)
        cam = self.current_camera()
        camera = Camera.from_dict(cam) if cam is not None else None
        return save_comparison(comparison, path, size or VIEW_SIZE, camera, scale)
