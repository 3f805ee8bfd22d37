"""The shape pair window: mesh A (the main window's) beside mesh B, a pick on one shows the
distance between shapes on the other.

It draws :class:`~modalviewer.viewer.pair.PairState` (``window.pair``, which scripts
drive) and keeps nothing else but VTK objects.  Its spectra go through the main window's
job queue and disk cache, reusing A's from the main window's state; the main window's
own display and pick are never changed.
"""

from __future__ import annotations

from pathlib import Path

from qtpy import QtCore, QtWidgets

from ..core.mesh import Mesh
from ..core.operators import DISTANCE_KINDS, operator_info
from ..scene.mesh_scene import MeshScene
from ..viewer.camera import Camera, CameraLink
from ..viewer.jobs import RUNNING
from ..viewer.pair import SIDES, PairView
from ..viewer.viewer import LONG_WAIT_SECONDS, ComputeError
from ..viewer.wording import seconds_text
from .dialogs import NO_MESH_A
from .panels.common import add_items, bind, row, show_values, slider, spin_box
from .status_bar import JobProgress
from .viewport import make_viewport
from .views_window import ViewsWindow

RESCALE_TIP = (
    "Scale both meshes to unit area before computing their spectra (distances are shown on "
    "the meshes as loaded): signatures carry a factor 1/area, and the Discrete Shells "
    "spectrum is not scale covariant. Untick only for meshes known to share one scale."
)
KIND_TIP = (
    "The signature compared: vibration (Discrete Shells), feature (E_D^N), heat kernel or "
    "wave kernel (Laplacian)"
)
SHARE_TIP = "Threshold: the share of the other mesh's area shown blue (the most similar points)"
LINK_TIP = "Turning or zooming one view turns the other the same way (each about its centre)"


class PairError(RuntimeError):
    """A scripted pair action failed; the message is for users."""


class PairWindow(ViewsWindow):
    """Two views, A (left) and B (right); see the module docstring."""

    EXPORT = ("pair.png", "Export the pair")

    def __init__(self, main, mesh_b: Mesh, path_b=None, k: int | None = None, force_offscreen=None):
        super().__init__(main, QtCore.Qt.WindowType.Window)
        self.setAcceptDrops(True)
        self.main = main
        state_a = main.state
        if state_a.mesh is None:
            raise PairError(NO_MESH_A)
        self.pair = main.viewer.pair(mesh_b, k=k, wait=False, path=path_b)
        self._closed = False
        self._syncing = False
        self._link = None
        self._build(force_offscreen)
        self._requested = self._wanted()  # what the spectra were last requested for: the
        # first request comes once the window is shown (the progress text fits its bar)
        self.pair.events.display.connect(self.redraw)
        self.pair.events.linked.connect(self._on_linked)
        self.pair.events.meshes.connect(self._on_meshes)
        self.pair.events.message.connect(self._on_message)
        main.viewer.jobs.events.changed.connect(self._on_jobs)
        state_a.events.mesh.connect(self._on_main_mesh)
        main.installEventFilter(self)
        self._on_meshes()
        self.resize(1200, 640)

    # ================================================================ UI
    def _build(self, force_offscreen) -> None:
        p = self.pair
        kinds = ((label, kind) for kind, label in DISTANCE_KINDS.items())
        self.kind_combo = add_items(QtWidgets.QComboBox(toolTip=KIND_TIP), kinds)
        displays = (("Continuous", "continuous"), ("Threshold", "threshold"))
        self.display_combo = add_items(QtWidgets.QComboBox(), displays)
        self.share_slider = slider(1, 500, SHARE_TIP)  # tenths of a percent of the other's area
        self.share_slider.valueChanged.connect(lambda v: p.set_display("threshold", v / 1000))
        self.share_label = QtWidgets.QLabel(minimumWidth=150)
        k_tip = "Modes computed on each mesh (the same on both)"
        self.k_spin = spin_box(2, 1000, tip=k_tip, prefix="k = ")
        self.k_spin.editingFinished.connect(lambda: setattr(p, "k", self.k_spin.value()))
        rescale = "Rescale both to the same area before computing"
        self.rescale_check = QtWidgets.QCheckBox(rescale, toolTip=RESCALE_TIP)
        self.link_check = QtWidgets.QCheckBox("Linked cameras", toolTip=LINK_TIP)
        self.controls = {  # the pair's field -> its widget
            "kind": self.kind_combo,
            "distance_display": self.display_combo,
            "rescale": self.rescale_check,
            "linked": self.link_check,
        }
        for name, widget in self.controls.items():
            bind(widget, lambda value, n=name: setattr(p, n, value))
        export_tip = "Both views side by side in one PNG"
        export = QtWidgets.QPushButton("Export...", toolTip=export_tip, clicked=self.export_dialog)
        layout = QtWidgets.QVBoxLayout(self)
        controls = (self.kind_combo, self.display_combo, self.share_slider, self.share_label)
        layout.addLayout(row("Distance", *controls, self.k_spin, 1, export))
        layout.addLayout(row(self.rescale_check, self.link_check, 1))
        views = QtWidgets.QHBoxLayout()
        self.viewports, self.titles = {}, {}
        for side in SIDES:
            column = QtWidgets.QVBoxLayout()
            self.titles[side] = QtWidgets.QLabel()
            viewport = self.viewports[side] = make_viewport(self, force_offscreen)
            viewport.clicked.connect(lambda x, y, s=side: self._on_click(s, x, y))
            viewport.cameraChanged.connect(lambda s=side: self._on_camera(s))
            column.addWidget(self.titles[side])
            column.addWidget(viewport.widget, 1)
            views.addLayout(column, 1)
        layout.addLayout(views, 1)
        self.status = QtWidgets.QLabel(wordWrap=True)
        self.job_progress = JobProgress((240, 320), "Cancel this window's work", p.cancel)
        progress = self.job_progress
        layout.addLayout(row((self.status, 1), progress.bar, progress.cancel_button))
        self.scenes: dict[str, MeshScene] = {}  # both from the window's first _on_meshes
        self._drawn: dict[str, tuple] = {}  # side -> (what is drawn, scene, values)
        self.install_keys(
            [("Escape", self._escape), ("Ctrl+W", self.close), ("R", self.reset_cameras)]
        )
        self._sync_controls()

    def _sync_controls(self) -> None:
        p = self.pair
        shown = [(widget, getattr(p, name)) for name, widget in self.controls.items()]
        numbers = [(self.share_slider, int(round(1000 * p.share))), (self.k_spin, p.k)]
        show_values(shown + numbers)
        self.share_slider.setEnabled(p.distance_display == "threshold")

    # ============================================================ meshes
    def _on_meshes(self) -> None:
        for side in SIDES:
            mesh = self.pair.drawn_mesh(side)
            scene = self.scenes.get(side)
            if scene is not None and scene.mesh is mesh:
                continue
            if scene is not None:
                scene.remove()
            plotter = self.viewports[side].plotter
            scene = MeshScene(plotter, mesh)
            scene.overlay_scale = getattr(self.main.scene, "overlay_scale", 1.0)
            self.scenes[side] = scene
            self.titles[side].setText(
                f"{side.upper()}: {self.pair.name(side)} ({mesh.n_vertices} vertices)"
            )
        self.setWindowTitle(
            f"modalviewer - shape pair: {self.pair.name('a')} / {self.pair.name('b')}"
        )
        self._start_views()
        self.redraw()

    def _on_main_mesh(self) -> None:
        """The main window opened another mesh: it becomes A (or the window closes)."""
        mesh = self.main.state.mesh
        if mesh is None:
            self.close()
            return
        self.pair.set_mesh("a", mesh, self.main.state.mesh_path)

    def dragEnterEvent(self, event):  # noqa: N802
        if event.mimeData().hasUrls():
            event.acceptProposedAction()

    def dropEvent(self, event):  # noqa: N802
        """A file dropped on the window replaces mesh B."""
        urls = event.mimeData().urls()
        mesh = self.main.read_mesh_file(urls[0].toLocalFile()) if urls else None
        if mesh is not None:
            self.pair.set_mesh("b", mesh, Path(urls[0].toLocalFile()))

    # =========================================================== drawing
    def redraw(self) -> None:
        """Draw both sides from the pair state; a side whose picture did not change is
        left alone, and a threshold move on the same distances only changes the colour
        table and the legend.  A new kind, k, scaling, mesh or pick requests the spectra
        it needs."""
        if self._closed:
            return
        if self._wanted() != self._requested:
            self.request()
        for side in SIDES:
            if self._draw(side, self.scenes[side], self.pair.view(side)):
                self.viewports[side].request_render()
        self._sync_controls()
        self._update_status()

    def _wanted(self) -> tuple:
        p = self.pair
        return p.key(), p.picked, p.drawn_mesh("a").hash, p.drawn_mesh("b").hash

    def _draw(self, side: str, scene: MeshScene, view: PairView) -> bool:
        """Bring ``scene`` to ``view`` from what it shows (``before``); False if it already
        showed it."""
        field = (None if view.values is None else id(view.values), view.colormap)
        whole = (field, view.threshold, view.legend, view.marker, view.back_marker)
        drawn = self._drawn.get(side)
        before = drawn[0] if drawn is not None and drawn[1] is scene else None
        if before == whole:
            return False
        if before is not None and before[0] == field:
            if view.colormap == "threshold" and before[1] != view.threshold:
                scene.set_threshold(view.threshold)
        elif view.values is None:
            scene.show_plain()
        elif view.colormap == "threshold":
            scene.show_threshold(view.values, view.threshold, name=view.colorbar_title)
        else:
            scene.show_field(
                view.values, "sequential", isolines=0, name=view.colorbar_title, scale=view.scale
            )
        scene.set_legend(view.legend)
        if view.values is None:
            scene.set_colorbar(None)
        else:
            scene.set_colorbar(view.colorbar_title, labels=view.colorbar_labels)
        if before is None or before[3] != view.marker:
            scene.show_marker(view.marker)
        if before is None or before[4] != view.back_marker:
            scene.show_back_marker(view.back_marker)
        # keep the values alive with the record, so their id cannot be reused
        self._drawn[side] = (whole, scene, view.values)
        return True

    def _update_status(self) -> None:
        p = self.pair
        threshold = p.distance_display == "threshold"
        self.share_label.setText(f"{100 * p.share:.1f} % of the other mesh" if threshold else "")
        match = p.best_match()
        if match is not None:
            side, w, dist = match
            text = f"Best match on {side.upper()}: vertex {w} (distance {dist:.3g})"
            back = p.back_match()
            text += "; mutual" if back == p.picked[1] else f"; not mutual (back: vertex {back})"
        elif p.picked is None:
            text = "Click a point on A or on B."
        else:
            text = p.view(SIDES[0]).legend.splitlines()[-1]
        self.status.setText(text)

    def _on_message(self, text: str) -> None:
        if self._closed:
            return
        self.status.setText(text)
        self.main.show_error(text, "Shape pair")

    def _on_jobs(self, _job=None) -> None:
        if self._closed:
            return
        pending = self.pair.pending()
        self.job_progress.show_jobs(sorted(pending, key=lambda job: job.status != RUNNING))

    # ========================================================== cameras
    def _on_linked(self, on: bool) -> None:
        """Linked cameras (``pair.linked``): the two views keep the relative viewpoint
        they have when the link is made (after opening or R: the same direction, each
        about its own mesh's centre), so turning, zooming or panning one view does the
        same to the other.  Free cameras: turn B by hand to line it up with A (a rotated
        copy), then link."""
        self._sync_controls()
        cameras = (_camera(self.viewports[side].plotter.camera) for side in SIDES)
        self._link = CameraLink.between(*cameras) if on else None  # A's to B's as they are

    def _on_camera(self, side: str) -> None:
        if self.pair.linked and not self._syncing:
            dst = "b" if side == "a" else "a"
            self._copy_camera(side, dst)
            self.viewports[dst].request_render()

    def _copy_camera(self, src: str, dst: str) -> None:
        """Move ``dst``'s camera to the image of ``src``'s under the link."""
        if self._link is None:
            return
        a = self.viewports[src].plotter.camera
        carried, factor = self._link.carry(_camera(a), from_a=src == "a")
        self._syncing = True
        try:
            self.scenes[dst].set_camera(carried, fit=False)
            b = self.viewports[dst].plotter.camera
            b.SetViewAngle(a.GetViewAngle())
            b.SetParallelProjection(a.GetParallelProjection())
            b.SetParallelScale(a.GetParallelScale() * factor)
        finally:
            self._syncing = False

    def _start_views(self) -> None:
        """A's canonical view; B seen from the same direction, about its own centre and
        at its own size (meshes in one frame, like a shape and its deformed copy, then
        show the same side); linked cameras are linked anew."""
        self.scenes["a"].reset_camera()
        self._link = CameraLink.facing(*(self.pair.drawn_mesh(side) for side in SIDES))
        self._copy_camera("a", "b")
        self._on_linked(self.pair.linked)

    def reset_cameras(self) -> None:
        """Back to the first views (R): see :meth:`_start_views`."""
        self._start_views()
        self.render_all()

    # ====================================================== interaction
    def _on_click(self, side: str, x: float, y: float) -> None:
        vertex = self.scenes[side].vertex_at_display(x, y)
        if vertex is not None:  # a spectrum missing or cancelled before is computed
            self.pair.pick(side, self.pair.drawn_mesh(side).file_vertex(vertex))
            self.request()

    def request(self) -> list:
        """Start the computations the current kind needs (the status says how long they
        take where that is long); returns the pending jobs."""
        self._requested = self._wanted()
        seconds = self.pair.estimated_seconds()
        if seconds is not None and seconds > LONG_WAIT_SECONDS:
            label = operator_info(self.pair.operator).label
            self.status.setText(
                f"Computing the {label} spectra of both meshes takes about "
                f"{seconds_text(seconds)} (Cancel stops it)."
            )
        jobs = self.pair.request()
        self._on_jobs()
        return jobs

    def wait(self, timeout: float | None = None) -> None:
        """Run the event loop until this window's spectra for the current kind are in;
        raises PairError if one could not be computed."""
        self.request()  # the window's status says what is computed and for how long
        try:
            self.main.viewer.wait_for_pair(self.pair)
        except ComputeError as exc:
            raise PairError(str(exc)) from None
        QtWidgets.QApplication.processEvents()

    # ============================================================ close
    def _escape(self) -> None:
        """Esc cancels this window's computations if any run (as in the main window),
        else closes the window."""
        if self.pair.pending():
            self.pair.cancel()
        else:
            self.close()

    def eventFilter(self, obj, event):  # noqa: N802
        if obj is self.main and event.type() == QtCore.QEvent.Type.Close:
            self.close()
        return False

    def closeEvent(self, event):  # noqa: N802
        if not self._closed:
            self._closed = True
            self.pair.cancel()
            self.main.viewer.jobs.events.changed.disconnect(self._on_jobs)
            self.main.state.events.mesh.disconnect(self._on_main_mesh)
            self.main.removeEventFilter(self)
            self.close_views()
            if getattr(self.main, "pair_window", None) is self:
                self.main.pair_window = None
        super().closeEvent(event)


def _camera(vtk_camera) -> Camera:
    return Camera(vtk_camera.GetPosition(), vtk_camera.GetFocalPoint(), vtk_camera.GetViewUp())


def open_pair_window(main, path, wait: bool = True, k: int | None = None) -> PairWindow | None:
    """Open ``path`` as mesh B beside the main window's mesh A (a previous pair window is
    closed).  With ``wait`` the call returns once both spectra are in (PairError if one
    fails); None (after a message) if there is no mesh A or ``path`` cannot be read."""
    if main.state.mesh is None:
        main.show_error(NO_MESH_A)
    mesh = main.read_mesh_file(path) if main.state.mesh is not None else None
    if mesh is None:
        if wait:
            raise PairError(main.last_error or f"cannot open {path}")
        return None
    previous = getattr(main, "pair_window", None)
    if previous is not None:
        previous.close()
    window = PairWindow(main, mesh, Path(path), k=k)
    main.pair_window = window
    window.show()
    window.request()
    if wait:
        window.wait()
    return window


__all__ = ["PairError", "PairWindow", "open_pair_window"]
