"""Pictures in scripts and notebooks: :func:`plot` (the viewer's picture, drawn off screen
by ``modalviewer render``'s renderer), :func:`view` (the desktop viewer on in-memory
data) and :func:`add_to_plotter` (a ``pyvista.Plotter`` of one's own); each imports
pyvista (and :func:`view` Qt) when called."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .core.operators import DISTANCE_KINDS
from .core.spectrum import Spectrum
from .extras import extra_needed
from .interop import as_mesh

DEFAULT_PLOT_SIZE = (800, 600)


class Picture:
    """An image: ``.array`` the (h, w, 3) or (h, w, 4) uint8 pixels; shown inline by
    Jupyter (``_repr_png_``); :meth:`save` writes a PNG."""

    def __init__(self, array: np.ndarray):
        self.array = np.ascontiguousarray(array)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.array.shape

    def _repr_png_(self) -> bytes:
        import io

        from PIL import Image

        out = io.BytesIO()
        Image.fromarray(self.array).save(out, format="PNG")
        return out.getvalue()

    def save(self, path) -> Path:
        """Write the picture to ``path`` as PNG (atomically); returns the path."""
        from .scene.export import save_png

        return save_png(Path(path), self.array)

    def __repr__(self) -> str:
        return f"Picture({self.array.shape[1]}x{self.array.shape[0]})"


class InteractivePicture:
    """The viewer's 3D scene as a standalone web page (vtk.js: turn, zoom and pan in the
    browser, no kernel or server needed), shown inline by Jupyter (``_repr_html_``, in an
    iframe) and in docs built from executed notebooks; :meth:`save` writes the page.
    ``legend``: the picture's legend (lines), written above the view."""

    def __init__(self, html: str, legend: str = "", size=DEFAULT_PLOT_SIZE):
        self.html = html
        self.legend = legend
        self.size = (int(size[0]), int(size[1]))

    def _repr_html_(self) -> str:
        import html as html_module

        page = html_module.escape(self.html, quote=True)
        legend = html_module.escape(self.legend).replace("\n", "<br>")
        w, h = self.size
        return (
            f'<div style="font-family:sans-serif;font-size:13px">{legend}</div>'
            f'<iframe srcdoc="{page}" width="{w}" height="{h}" '
            'style="border:none" sandbox="allow-scripts"></iframe>'
        )

    def save(self, path) -> Path:
        """Write the page to ``path`` (.html), atomically; returns the path."""
        from .core.files import atomic_write

        path = Path(path)
        if path.suffix.lower() not in (".html", ".htm"):
            path = path.with_suffix(".html")
        return atomic_write(path, lambda tmp: Path(tmp).write_text(self.html, encoding="utf-8"))

    def __repr__(self) -> str:
        return f"InteractivePicture({len(self.html) / 2**20:.1f} MB page)"


def interactive_available() -> bool:
    """Whether the page export (trame-pyvista and trame-vtk) is installed."""
    import importlib.util

    return all(importlib.util.find_spec(m) is not None for m in ("trame_pyvista", "trame_vtk"))


def _field_of(field, n: int):
    """(name, values) of ``field``: an array, a (name, array) pair or a one-item dict."""
    if isinstance(field, dict):
        if not field:
            raise ValueError("fields is empty")
        name, values = next(iter(field.items()))
    elif isinstance(field, tuple) and len(field) == 2 and isinstance(field[0], str):
        name, values = field
    else:
        name, values = "field", field
    values = np.asarray(values, dtype=np.float64)
    if values.shape != (n,):
        raise ValueError(f"a field has one value per mesh vertex, ({n},); got {values.shape}")
    return str(name), values


def _prepared_viewer(mesh, spectrum, mode, vertex, kind, k, viewer=None):
    """``viewer`` (default a new one) showing what :func:`plot` draws of ``mesh``."""
    from .core.operators import operator_for_distance
    from .viewer import Viewer

    if mode is not None and spectrum is None:  # it drew the plain mesh without a word
        raise ValueError(
            f"mode={mode} is a mode of a spectrum: pass one, e.g. "
            f"plot(mesh, mv.compute_spectrum(mesh, 'laplacian', k), mode={mode})"
        )
    viewer = viewer or Viewer()
    viewer.set_mesh(mesh)
    if spectrum is not None:
        viewer.add_spectrum(spectrum)
    if vertex is not None:
        kind = distance_kind_of(spectrum, kind)
        needed = operator_for_distance(kind)
        if viewer.state.spectrum(needed) is None:
            viewer.compute(needed, k=k, wait=True)
        viewer.state.set_display(distance_kind=kind)
        viewer.state.set_pick_file_vertex(int(vertex))
        viewer.show_distance(kind, display="continuous")
    elif spectrum is not None:
        j = viewer.state.first_nonzero_mode(spectrum.operator) if mode is None else int(mode)
        if not 0 <= j < spectrum.k:
            raise ValueError(f"mode must be between 0 and {spectrum.k - 1}, got {mode}")
        viewer.show_mode(j, spectrum.operator)
    return viewer


def distance_kind_of(spectrum: Spectrum | None, kind: str | None) -> str:
    """``kind``, or where it is None the distance ``spectrum`` defines (heat kernel for
    the Laplacian, feature for E_D^N, vibration for the 3D shells), or "vibration"
    without a spectrum."""
    if kind is not None:
        return kind
    own = "vibration" if spectrum is None else spectrum.operator_info.distance_kind
    if own is None:
        raise ValueError(
            f"a {spectrum.operator} spectrum defines no distance; pass kind= (one of "
            f"{', '.join(DISTANCE_KINDS)})"
        )
    return own


@extra_needed("mv.plot")
def plot(
    mesh,
    spectrum: Spectrum | None = None,
    mode: int | None = None,
    field=None,
    kind: str | None = None,
    vertex: int | None = None,
    screenshot=None,
    size=DEFAULT_PLOT_SIZE,
    k: int = 50,
    transparent: bool = False,
    interactive: bool = False,
    animate: bool = False,
    frames: int | None = None,
    fps: float = 25,
    modes=None,
    grid=None,
):
    """The viewer's picture of ``mesh`` (anything :func:`~modalviewer.as_mesh` takes, or
    a file) rendered off screen at ``size``, as a :class:`Picture`, also written to
    ``screenshot`` if given: mode ``mode`` of ``spectrum`` (default its first non-zero
    one); or per-vertex ``field`` values (an (n,) array in ``mesh``'s numbering, NaN
    allowed at ``mesh.unused``, a ``(name, values)`` pair or a dict's first item; signed
    values in the modes' colours, others white to red); or the ``kind`` distance map
    ("vibration", "feature", "hks", "wks"; default the distance of ``spectrum``'s
    operator, or "vibration") from ``vertex`` (the input's numbering), from ``spectrum``
    where it is the kind's, else from ``k`` modes computed and cached as in the viewer.

    ``interactive``: an :class:`InteractivePicture` to turn in the notebook (the
    ``notebook`` extra; without it a :class:`Picture` and a warning saying how to install
    it).  ``modes``: those modes side by side, one camera and colour bar (``grid``
    (columns, rows), default rows of up to 4; ``size`` per panel).  ``animate``: the mode
    vibrating, one period in ``frames`` frames (default: the window's speed) at ``fps``,
    as an :class:`~modalviewer.scene.animation.Animation` (a looping GIF; ``screenshot``
    then names a .gif, or a .mp4 where imageio-ffmpeg is installed).
    """
    mesh = as_mesh(mesh)
    viewer = _prepared_viewer(mesh, spectrum, mode, vertex, kind, k)
    try:
        if field is not None:
            name, values = _field_of(field, mesh.n_vertices)
            viewer.show_field(name, values)
        if interactive and not interactive_available():
            import warnings

            warnings.warn(
                "an interactive picture needs trame-pyvista and trame-vtk: pip install "
                "'modalviewer[notebook]'; showing an image instead",
                stacklevel=2,
            )
            interactive = False
        if modes is not None:
            if spectrum is None:
                raise ValueError("modes= are modes of a spectrum: pass one")
            picture = Picture(viewer.mode_grid(modes, spectrum.operator, grid, size))
        elif animate:
            from .scene.animation import Animation

            picture = Animation(viewer.animation_images(frames, fps, size), fps)
        elif interactive:
            # the scene an image is made of (surface, isolines, marker) as a vtk.js page
            renderer = viewer.renderer(size)
            renderer.plotter.render()
            html = renderer.plotter.trame.export_html(None).getvalue()
            field = viewer.state.derived.field()
            picture = InteractivePicture(html, field.legend if field is not None else "", size)
        else:
            picture = Picture(viewer.image(transparent=transparent, size=size))
    finally:
        viewer.close()
    if screenshot is not None:
        picture.save(screenshot)
    return picture


@extra_needed("mv.view (the desktop viewer)")
def view(mesh_or_arrays, spectrum: Spectrum | None = None, fields=None, block: bool = True):
    """Open the desktop viewer on anything :func:`~modalviewer.as_mesh` accepts, or a
    file; returns the window (``.viewer`` its :class:`~modalviewer.viewer.Viewer`) when
    it closes, or at once with ``block=False`` (a notebook with ``%gui qt``, a script
    running the Qt loop).  ``spectrum`` is shown from its first non-zero mode; ``fields``
    (name -> per-vertex array) become the viewer's fields, the first shown."""
    mesh = as_mesh(mesh_or_arrays)
    from .gui.application import ensure_application
    from .gui.main_window import MainWindow
    from .viewer import Viewer

    app = ensure_application()
    viewer = Viewer()
    window = MainWindow(viewer=viewer)  # before the mesh: the window draws what follows
    _prepared_viewer(mesh, spectrum, None, None, None, 0, viewer)
    if fields:
        _field_of(fields, mesh.n_vertices)  # checked as plot checks them
        for name, values in fields.items():
            viewer.state.add_field(name, values)
        viewer.show_field(next(iter(fields)))
    window.show()
    if block:
        app.exec()
    return window


@extra_needed("mv.add_to_plotter")
def add_to_plotter(
    plotter,
    mesh,
    values_or_spectrum,
    mode: int | None = None,
    vertex: int | None = None,
    isolines: int = 0,
    name: str = "",
):
    """Add ``mesh`` coloured as the viewer colours it to ``plotter`` (a
    ``pyvista.Plotter``); returns the :class:`~modalviewer.scene.mesh_scene.MeshScene`
    holding its actors (the vertices faces use).  ``values_or_spectrum``: per-vertex
    values in ``mesh``'s numbering (signed: diverging colours, else white to red), or a
    :class:`Spectrum`: its mode ``mode`` (default the first non-zero one; vector modes by
    their normal component) or, with ``vertex``, the multiscale distance from it."""
    from .core.laplacian import vertex_normals
    from .core.signatures import multiscale_distance
    from .core.spectrum import on_solver_mesh
    from .scene.mesh_scene import MeshScene

    mesh = as_mesh(mesh)
    solver = mesh.solver_mesh  # the vertices faces use: what is drawn
    normals = vertex_normals(solver)
    scene = MeshScene(plotter, solver, normals)
    if not isinstance(values_or_spectrum, Spectrum):
        values = np.asarray(values_or_spectrum, dtype=np.float64)
        if values.shape != (mesh.n_vertices,):
            raise ValueError(f"one value per mesh vertex, ({mesh.n_vertices},); got {values.shape}")
        if solver is not mesh:
            values = values[solver.file_vertices]
        signed = float(values.min()) < 0.0 < float(values.max())
        kind = "diverging" if signed else "sequential"
    elif vertex is not None:
        spec = on_solver_mesh(values_or_spectrum, solver)
        values = multiscale_distance(spec, solver.mesh_vertex(int(vertex)))
        kind, name = "sequential", name or "distance"
    else:
        from .viewer.mode_scalar import mode_scalar, smoothed_normals

        spec = on_solver_mesh(values_or_spectrum, solver)
        if mode is None:  # the first non-zero mode (0 if all are zero)
            mode = int(np.argmax(~spec.zero_mode_mask()))
        values = mode_scalar(
            spec, int(mode), smoothed_normals(solver) if spec.is_vector else normals
        )
        kind, name = "diverging", name or f"mode {mode}"
    scene.show_field(values, kind, isolines=isolines, name=name)
    return scene
