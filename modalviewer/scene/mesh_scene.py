"""The surface with a per-vertex field, isolines, a pick marker, animation.  Updates reuse
the ``PolyData`` and actors: switching a mode or a threshold costs one array copy, the
isolines and a render."""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkRenderingCore import vtkActor2D, vtkCellPicker, vtkImageMapper

from ..core.laplacian import vertex_normals
from ..core.mesh import Mesh
from ..viewer import camera as cameras
from .colors import (
    COLORMAPS,
    DEFAULT_STYLE,
    DIVERGING,
    RED,
    SEQUENTIAL,
    STYLES,
    THRESHOLD,
    WHITE,
)
from .framing import view_angle_on_smaller_side
from .isolines import line_polydata, meaningful_zero_lines, segments
from .overlay import ColorBar, Overlay, draw_overlay

# The rest shape behind a deformed mode: a translucent grey copy (faint but visible on
# the white background of the paper style).
GHOST_GREY = (0.55, 0.55, 0.6)
GHOST_OPACITY = 0.18
SURFACE_DEPTH_OFFSET = (2.0, 4.0)
"""Polygon offset (factor, units) of the surface: it stands back in depth from its
isolines, which lie on it."""
GHOST_DEPTH_OFFSET = (0.0, 1e8)
"""Polygon offset (factor, units) of the rest shape's ghost: it pushes every ghost
fragment to the back of the depth range, so the ghost shows only where no surface is
drawn, as structural-analysis tools draw the undeformed shape; at its true depth it
would grey the surface over in stair-stepped patches wherever the two cross."""
GHOST_FADE = (0.005, 0.02)
"""Shares of the bounding-box diagonal: the ghost is not drawn where a vertex moves less
than the first, drawn at :data:`GHOST_OPACITY` from the second, linearly between (near
the rest shape it would only add grey rims along the outline)."""


def add_actor(plotter, data, name: str, **options):
    """``plotter.add_mesh`` of an actor beside the surface: no render, the camera kept,
    no scalar bar of pyvista's own, one colour unless ``options`` give scalars."""
    options = {"scalars": None, **options}
    return plotter.add_mesh(
        data, name=name, render=False, reset_camera=False, show_scalar_bar=False, **options
    )


class MeshScene:
    """Owns the actors of one mesh on a pyvista plotter."""

    def __init__(
        self, plotter, mesh: Mesh, normals: np.ndarray | None = None, style: str = DEFAULT_STYLE
    ):
        if normals is None:
            normals = vertex_normals(mesh)
        self.plotter = plotter
        self.mesh = mesh
        self.normals = normals
        self.rest_points = np.array(mesh.vertices)
        self.surface = self._rest_shape()
        self.surface.point_data["field"] = np.zeros(mesh.n_vertices)
        self.surface.point_data["displacement"] = np.zeros((mesh.n_vertices, 3))
        self.surface.set_active_scalars("field")
        # Our own vertex normals and Phong interpolation instead of pyvista's smooth_shading,
        # which would draw a filtered copy that our in-place updates do not reach.
        self.surface_actor = plotter.add_mesh(
            self.surface,
            scalars="field",
            show_scalar_bar=False,
            interpolation="phong",
            name="surface",
            reset_camera=True,
        )
        self._mapper = self.surface_actor.mapper
        self._mapper.SetInputData(self.surface)
        self._mapper.SetScalarModeToUsePointFieldData()
        self._mapper.SelectColorArray("field")
        self._mapper.SetUseLookupTableScalarRange(False)
        # plain light grey until a field is shown (the all-zero field would take the
        # bottom colour of pyvista's default colour map, a dark purple)
        self._mapper.ScalarVisibilityOff()
        self.surface_actor.prop.color = (0.86, 0.86, 0.86)
        # Push the surface slightly back in depth so the isolines lying on it are not
        # half hidden by depth fighting.
        self._mapper.SetResolveCoincidentTopologyToPolygonOffset()
        self._mapper.SetRelativeCoincidentTopologyPolygonOffsetParameters(*SURFACE_DEPTH_OFFSET)
        self.isolines = pv.PolyData()
        self.zero_line = pv.PolyData()
        self.iso_actor = self.zero_actor = None
        # (rest points, displacement) of the isolines and the zero line, for the animation
        self._iso_rest = self._iso_disp = self._zero_rest = self._zero_disp = None
        self.marker_actor = self.back_marker_actor = None
        self.ghost_actor = None  # the rest shape, faint, behind a displaced surface
        self._ghost_rest = None  # its mesh
        self.picker = vtkCellPicker()
        self.picker.SetTolerance(1e-4)
        self.picker.PickFromListOn()
        self.picker.AddPickList(self.surface_actor)
        self.field_name = ""
        self._values: np.ndarray | None = None  # the field of show_field, unscaled
        self.scale: tuple | None = None  # a spread colour scale's knots (show_field)
        self.clim = (0.0, 1.0)
        self.clipped = (False, False)  # values beyond the low / high end of clim
        self.kind = "plain"
        self.threshold: float | None = None  # of a map made by show_threshold
        self.style = ""
        self.set_style(style)
        # legend and colour bar: what the caller asked for, and their on-screen actors
        self.legend_text: str | None = None
        self.colorbar_title: str | None = None
        self.colorbar_labels: list[str] | None = None
        # drawn by Pillow into one transparent image over the view (the same drawing as
        # in exports), redrawn before a render when the text or the view's size changed
        self.overlay_actor = None
        # text size factor: the device pixel ratio of the screen (2 on a HiDPI display,
        # where the render window counts device pixels); exports multiply their scale by it
        self.overlay_scale = 1.0
        self._overlay_key = None
        self._overlay_observer = None
        # canonical first view of this mesh; the scene keeps a reference on the plotter so
        # an export of the plotter finds the scene's legend and colour bar
        self.up_axis: str | None = None  # None or "auto": detected (:meth:`up`)
        self._up: tuple | None = None  # (up_axis, the axis in effect) of the last call
        self._canonical: tuple | None = None  # (up axis, its canonical camera)
        plotter._modalviewer_scene = self

    def _rest_shape(self) -> pv.PolyData:
        """A copy of the rest shape with our vertex normals as VTK's normals."""
        poly = pv.PolyData.from_regular_faces(self.rest_points.copy(), self.mesh.faces)
        poly.point_data["Normals"] = self.normals
        poly.GetPointData().SetNormals(poly.GetPointData().GetArray("Normals"))
        return poly

    # ------------------------------------------------------------------ style
    def set_style(self, style: str) -> None:
        """Switch the rendering style: "paper" (white zero, saturated colours, headlight)
        or "shaded" (pyvista's light kit, plain diffuse); see ``STYLES``.  No render."""
        if style not in STYLES:
            raise ValueError(f"unknown style {style!r}; choose one of {', '.join(STYLES)}")
        params = STYLES[style]
        self.plotter.remove_all_lights()
        if params["lights"] == "headlight":
            self.plotter.add_light(pv.Light(light_type="headlight", intensity=1.0))
        else:
            self.plotter.enable_lightkit()
        for term in ("ambient", "diffuse", "specular"):
            setattr(self.surface_actor.prop, term, params[term])
        self.style = style

    # ----------------------------------------------------------------- fields
    def show_field(
        self,
        values: np.ndarray,
        kind: str = "diverging",
        clim: tuple[float, float] | None = None,
        isolines: int = 0,
        displacement: np.ndarray | None = None,
        name: str = "",
        clipped: tuple[bool, bool] = (False, False),
        scale: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        """Colour the surface by ``values`` in the colour map of ``kind`` (see ``COLORMAPS``;
        "threshold": :meth:`show_threshold`), the zero isoline bold on a diverging field;
        a sequential field's spread ``scale`` (knot values, knot positions) colours
        ``np.interp(values, *scale)`` while its colour bar keeps the values."""
        values = np.array(values, dtype=np.float64)  # the animation rewrites the copy drawn
        self.scale = None
        if scale is not None and kind == "sequential":
            self.scale = (np.asarray(scale[0], float), np.asarray(scale[1], float))
            true_range = (float(self.scale[0][0]), float(self.scale[0][-1]))
            values = np.interp(values, *self.scale)
            clim = (0.0, 1.0)
        self._values = values
        self.surface.point_data["field"] = values.copy()
        if displacement is not None:
            self.surface.point_data["displacement"] = displacement
        if clim is None:  # the default range of each kind
            top, a = float(np.max(values)) or 1.0, float(np.max(np.abs(values))) or 1.0
            ranges = {"diverging": (-a, a), "sequential": (0.0, top), "threshold": (0.0, 1.0)}
            clim = ranges.get(kind, (float(values.min()), top))
        self._mapper.lookup_table = {"diverging": DIVERGING, "threshold": THRESHOLD}.get(
            kind, SEQUENTIAL
        )
        self._mapper.scalar_range = clim
        self._mapper.ScalarVisibilityOn()
        self.clim = clim
        self.clipped = (bool(clipped[0]), bool(clipped[1]))
        self.kind = kind
        self.field_name = name
        self._overlay_changed()
        self.set_isolines(values, isolines if kind != "threshold" else 0, kind == "diverging")
        if self.scale is not None:
            self.clim = true_range  # what the colour bar says

    def set_isolines(self, values: np.ndarray, count: int, emphasise_zero: bool) -> None:
        """Contour the rest shape (so the lines can follow the animation) at ``count`` levels."""
        lo, hi = self.clim
        levels = np.linspace(lo, hi, count + 2)[1:-1] if count > 0 else np.zeros(0)
        if emphasise_zero:
            levels = levels[np.abs(levels) > 1e-12 * max(abs(lo), abs(hi))]
        want_zero = count > 0 and emphasise_zero and lo < 0 < hi
        # one pass over the triangles for all levels, the zero line split off after
        everything = list(levels) + ([0.0] if want_zero else [])
        faces, rest = self.mesh.faces, self.rest_points
        moves = self.surface.point_data["displacement"]
        seg, disp, level, tri, edges = segments(rest, faces, values, everything, moves)
        zero = level == 0.0 if want_zero else np.zeros(len(level), dtype=bool)
        if want_zero:
            diagonal = self.mesh.bounding_box_diagonal
            keep = meaningful_zero_lines(faces, rest, values, tri[zero], edges[zero], diagonal)
            drop = np.flatnonzero(zero)[~keep]
            seg, disp, zero = (np.delete(x, drop, axis=0) for x in (seg, disp, zero))
        self._iso_rest, self._iso_disp = self._show_lines(
            self.isolines, seg[~zero], disp[~zero], 1.5, "iso_actor"
        )
        self._zero_rest, self._zero_disp = self._show_lines(
            self.zero_line, seg[zero], disp[zero], 3.5, "zero_actor"
        )

    def _show_lines(
        self, lines: pv.PolyData, seg: np.ndarray, disp: np.ndarray, width: float, attr: str
    ):
        """Draw the black segments ``seg`` (s, 2, 3) in ``lines`` (none: hide the actor);
        returns their (rest points, displacement), or (None, None)."""
        actor = getattr(self, attr)
        if len(seg) == 0:
            if actor is not None:
                actor.SetVisibility(False)
            return None, None
        lines.copy_from(line_polydata(seg, disp), deep=False)
        if actor is None:
            # drawn as screen-space tubes: plain wide lines leave gaps between the
            # sub-pixel segments of fine meshes (the isolines would look dotted)
            tubes = {"render_lines_as_tubes": True}
            actor = add_actor(self.plotter, lines, attr, color="black", line_width=width, **tubes)
            setattr(self, attr, actor)
        actor.SetVisibility(True)
        # copies: the animation writes into the line points in place
        return seg.reshape(-1, 3).copy(), disp.reshape(-1, 3).copy()

    def show_threshold(self, distances: np.ndarray, threshold: float, name: str = "") -> None:
        """Threshold map drawn from the distances themselves: blue where d <= threshold,
        white elsewhere.  The colour is looked up after interpolation, so the boundary
        follows the interpolated crossing instead of a staircase along triangle edges;
        the table steps at the middle of the scalar range, which :meth:`set_threshold`
        centres on the threshold, so the step lies exactly on it however small."""
        values = np.asarray(distances, dtype=np.float64)
        self.show_field(values, "threshold", clim=(0.0, float(np.max(values)) or 1.0), name=name)
        self._mapper.SetInterpolateScalarsBeforeMapping(True)
        self.set_threshold(threshold)

    def set_threshold(self, threshold: float) -> None:
        """Move a :meth:`show_threshold` map's threshold (its scalar range's centre)."""
        lo, hi = self.clim
        reach = max(threshold - lo, hi - threshold, 1e-300)
        self._mapper.scalar_range = (threshold - reach, threshold + reach)
        self.threshold = float(threshold)
        self._overlay_changed()

    def show_plain(self) -> None:
        """The plain light-grey surface, no field and no isolines (a fresh mesh)."""
        self.surface.point_data["field"] = np.zeros(self.mesh.n_vertices)
        self.scale = None
        self._mapper.ScalarVisibilityOff()
        self.field_name = ""
        self.kind = "plain"
        for actor in (self.iso_actor, self.zero_actor):
            if actor is not None:
                actor.SetVisibility(False)
        self._iso_rest = self._zero_rest = None
        self._overlay_changed()

    # ------------------------------------------------------ legend, colour bar
    def set_legend(self, text: str | None) -> None:
        """Show ``text`` at the top left of the view and in exports; None or "" removes it."""
        self.legend_text = text or None
        self._overlay_changed()

    def set_colorbar(
        self, title: str | None, clim: tuple[float, float] | None = None, labels=None
    ) -> None:
        """Show a colour bar titled ``title`` (None hides it), ranged ``clim`` (default the
        field's); a threshold map's is two swatches labelled ``labels``."""
        self.colorbar_title = title
        self.colorbar_labels = list(labels) if labels is not None else None
        if clim is not None:
            self.clim = (float(clim[0]), float(clim[1]))
            if self.scale is None:  # a spread scale's colours span 0..1 of its knots
                self._mapper.scalar_range = self.clim
        self._overlay_changed()

    def colorbar(self, title: str | None = None) -> ColorBar | None:
        """The colour bar as drawn (None when hidden or nothing is coloured), or titled
        ``title`` when given (shown or not)."""
        title = title or self.colorbar_title
        if title is None or self.kind == "plain" and not self.field_name:
            return None
        colors = [np.asarray(c, dtype=float) for c in COLORMAPS.get(self.kind, [WHITE, RED])]
        if self.kind == "threshold":
            labels = self.colorbar_labels or [title, "the rest"]
            return ColorBar("", colors, (0.0, 1.0), "swatches", labels[:2])
        ticks = []
        if self.scale is not None and self.kind == "sequential":
            from ..viewer.color_scale import tick_values

            ticks = tick_values(self.scale)
        return ColorBar(title, colors, tuple(self.clim), clipped=self.clipped, ticks=ticks)

    def overlay(self, legend: bool = True, colorbar: bool | None = None) -> Overlay:
        """Legend and colour bar for an export: the legend if ``legend`` and set; the
        colour bar if shown (``colorbar`` None), or forced on/off."""
        bar = None if colorbar is False else self.colorbar()
        if colorbar is True and bar is None and self.kind != "plain":
            bar = self.colorbar(self.field_name or "value")
        return Overlay(self.legend_text if legend else None, bar)

    def _overlay_changed(self) -> None:
        """Legend or colour bar changed: make sure the overlay actor exists (it redraws
        itself before the next render)."""
        self._overlay_key = None
        if self.overlay_actor is None and (self.legend_text or self.colorbar() is not None):
            mapper = vtkImageMapper()
            mapper.SetColorWindow(255.0)
            mapper.SetColorLevel(127.5)
            actor = vtkActor2D()
            actor.SetMapper(mapper)
            actor.PickableOff()
            self.plotter.renderer.AddViewProp(actor)
            self.overlay_actor = actor
            self._overlay_observer = self.plotter.renderer.AddObserver(
                "StartEvent", self._refresh_overlay
            )

    def _refresh_overlay(self, *_args) -> None:
        """Redraw the overlay image if the legend, colour bar or view size changed."""
        actor = self.overlay_actor
        if actor is None or not actor.GetVisibility():
            return
        w, h = self.plotter.renderer.GetSize()
        overlay = self.overlay()
        key = (w, h, self.overlay_scale, repr(overlay))
        if key == self._overlay_key or w < 2 or h < 2:
            return
        self._overlay_key = key
        rgba = draw_overlay(np.zeros((h, w, 4), np.uint8), overlay, self.overlay_scale)
        image = vtkImageData()
        image.SetDimensions(w, h, 1)
        scalars = numpy_to_vtk(rgba[::-1].reshape(-1, 4).copy(), deep=True)
        scalars.SetNumberOfComponents(4)
        image.GetPointData().SetScalars(scalars)
        actor.GetMapper().SetInputData(image)

    # ----------------------------------------------------------------- camera
    def canonical_camera(self) -> cameras.Camera:
        """The canonical first view, computed once per up axis (seconds on a large mesh,
        and R must reset the view at once)."""
        up = self.up()
        if self._canonical is None or self._canonical[0] != up:
            camera = cameras.canonical_view(self.mesh.vertices, self.mesh.faces, up=up)
            self._canonical = (up, camera)
        return self._canonical[1]

    def up(self) -> str:
        """The up axis in effect: :attr:`up_axis`, else the one detected, so that a picture
        of a mesh alone (pair window, notebook plots) stands a Z-up scan upright too."""
        if self._up is None or self._up[0] != self.up_axis:
            axis = cameras.up_axis_of(self.mesh.vertices, self.mesh.faces, self.up_axis)
            self._up = (self.up_axis, axis)
        return self._up[1]

    def set_camera(self, camera: cameras.Camera, fit: bool = True) -> None:
        """Put the camera at ``camera``; ``fit``: then move it so the whole mesh is in view."""
        cam = self.plotter.camera
        cam.SetFocalPoint(*camera.focal_point)
        cam.SetPosition(*camera.position)
        cam.SetViewUp(*camera.up)
        cam.OrthogonalizeViewUp()
        if fit:
            view_angle_on_smaller_side(self.plotter.renderer)
            self.plotter.renderer.ResetCamera(*self.surface.bounds)
        self.plotter.renderer.ResetCameraClippingRange()

    def reset_camera(self, preset: str = "canonical") -> cameras.Camera:
        """Set and return camera ``preset``: the canonical first view (R), "isometric" or a
        side ("+x")."""
        if preset == "canonical":
            camera = self.canonical_camera()
        else:
            camera = cameras.preset_view(self.mesh.vertices, preset, up=self.up())
        self.set_camera(camera)
        return camera

    # -------------------------------------------------------------- animation
    def set_displacement_scale(self, s: float) -> None:
        """Move the surface (and isolines) to rest + s * displacement; no render."""
        disp = self.surface.point_data["displacement"]
        self._move(self.surface, self.rest_points, disp, s)
        for line, rest, d in (
            (self.isolines, self._iso_rest, self._iso_disp),
            (self.zero_line, self._zero_rest, self._zero_disp),
        ):
            if rest is not None:
                self._move(line, rest, d, s)

    def set_color_factor(self, factor: float) -> None:
        """Colour a diverging field as ``factor`` times its values: a signed mode's colours
        change sign as it vibrates."""
        if self.kind != "diverging" or self._values is None:
            return
        field = self.surface.point_data["field"]  # a view of the VTK array
        np.multiply(self._values, factor, out=field)
        self.surface.GetPointData().GetArray("field").Modified()

    def motion_points(self, reach: float, both: bool = True, most: int = 20000) -> np.ndarray:
        """The rest shape and the surface displaced by ``reach`` (and ``-reach`` with
        ``both``), at most ``most`` vertices each: what a picture of them must hold."""
        step = max(1, -(-self.mesh.n_vertices // most))
        rest = self.rest_points[::step]
        disp = np.asarray(self.surface.point_data["displacement"])[::step]
        if reach == 0.0 or not np.any(disp):
            return rest
        moved = [rest + reach * disp] + ([rest - reach * disp] if both else [])
        return np.concatenate([rest, *moved])

    def set_ghost(self, visible: bool, reach: float = 0.0) -> None:
        """Show (or hide) the rest shape as a faint grey copy behind the surface displaced
        by ``reach``, faded where it moves little (:meth:`ghost_opacities`)."""
        if self.ghost_actor is None:
            if not visible:
                return
            rest = self._rest_shape()
            rgba = np.zeros((self.mesh.n_vertices, 4), np.uint8)
            rgba[:, :3] = np.round(np.asarray(GHOST_GREY) * 255).astype(np.uint8)
            rest.point_data["ghost_rgba"] = rgba  # the opacities follow the mode shown
            self._ghost_rest = rest
            self.ghost_actor = add_actor(
                self.plotter,
                rest,
                "ghost",
                scalars="ghost_rgba",
                rgba=True,
                interpolation="phong",
                pickable=False,
            )
            # at the back of the depth range (GHOST_DEPTH_OFFSET): the surface always
            # covers it
            self.ghost_actor.mapper.SetRelativeCoincidentTopologyPolygonOffsetParameters(
                *GHOST_DEPTH_OFFSET
            )
        if visible:
            rgba = self._ghost_rest.point_data["ghost_rgba"]
            rgba[:, 3] = np.round(255 * self.ghost_opacities(reach)).astype(np.uint8)
            self._ghost_rest.GetPointData().GetArray("ghost_rgba").Modified()
        self.ghost_actor.SetVisibility(bool(visible))

    def ghost_opacities(self, reach: float) -> np.ndarray:
        """Per-vertex ghost opacity at ``reach``: ramps with the move over :data:`GHOST_FADE`."""
        moved = np.linalg.norm(self.surface.point_data["displacement"], axis=1) * abs(reach)
        low, high = (share * self.mesh.bounding_box_diagonal for share in GHOST_FADE)
        return GHOST_OPACITY * np.clip((moved - low) / (high - low), 0.0, 1.0)

    @staticmethod
    def _move(poly: pv.PolyData, rest: np.ndarray, disp: np.ndarray, s: float) -> None:
        """In place: points = rest + s * disp, then flag the VTK points as modified."""
        pts = np.asarray(poly.points)  # a view of the VTK array
        np.multiply(disp, s, out=pts)
        pts += rest
        poly.GetPoints().Modified()

    # ---------------------------------------------------------------- picking
    def vertex_at_display(self, x: float, y: float) -> int | None:
        """Vertex nearest to the surface point under display pixel (x, y), origin bottom left."""
        renderer = self.plotter.renderer
        if not self.picker.Pick(x, y, 0, renderer):
            return None
        cell = self.picker.GetCellId()
        if cell < 0:
            return None
        hit = np.array(self.picker.GetPickPosition())
        corners = self.mesh.faces[cell]
        d = np.linalg.norm(self.surface.points[corners] - hit, axis=1)
        return int(corners[np.argmin(d)])

    def show_marker(self, vertex: int | None) -> None:
        """The pick marker, a magenta sphere, at ``vertex`` (None: none).  No render."""
        self._sphere("marker_actor", "marker", vertex, 0.012, (0.9, 0.1, 0.6))

    def show_back_marker(self, vertex: int | None) -> None:
        """A smaller yellow sphere at ``vertex``: where the shape pair's best match leads back."""
        self._sphere("back_marker_actor", "back_marker", vertex, 0.009, (1.0, 0.75, 0.0))

    def _sphere(self, attr: str, name: str, vertex, size: float, color) -> None:
        if getattr(self, attr) is not None:
            self.plotter.remove_actor(getattr(self, attr), render=False)
        setattr(self, attr, None)
        if vertex is None:
            return
        radius = size * self.mesh.bounding_box_diagonal
        sphere = pv.Sphere(radius=radius, center=self.surface.points[vertex])
        setattr(self, attr, add_actor(self.plotter, sphere, name, color=color))

    def remove(self) -> None:
        for name in ("surface", "iso_actor", "zero_actor", "marker", "back_marker", "ghost"):
            self.plotter.remove_actor(name, render=False)
        if self.overlay_actor is not None:
            self.plotter.renderer.RemoveViewProp(self.overlay_actor)
        if self._overlay_observer is not None:
            self.plotter.renderer.RemoveObserver(self._overlay_observer)
        self.overlay_actor = self._overlay_observer = None
        if getattr(self.plotter, "_modalviewer_scene", None) is self:
            self.plotter._modalviewer_scene = None
