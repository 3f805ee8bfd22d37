"""The main window: wires the viewer model to the docks, the 3D view and the menus.

The state lives in :class:`~modalviewer.viewer.model.ViewerModel` (``win.model``,
``win.state``); panels and the scene observe it.  The methods below are the scripting
interface; each does what the matching click does, through the model::

    win.open_mesh(path); win.compute("shells", k=50, wait=True); win.show_mode(7)
    win.pick_file_vertex(123); win.show_distance("vibration", display="threshold", threshold=0.2)
    win.export_screenshot("fig.png", scale=2, transparent=True)
    win.save_session("s.json"); win.open_session("s.json", wait=True)
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np
from qtpy import QtCore, QtWidgets

from ..core.cache import SpectrumCache
from ..core.mesh import Mesh, MeshError
from ..core.operators import DISTANCE_KINDS, OPERATOR_INFO, operator_for_distance
from ..core.spectrum import Spectrum
from ..readers import DamagedFileError
from ..viewer.jobs import DONE, Job
from ..viewer.model import (
    ComputeRefused,
    ViewerModel,
    cost_estimate,
    repair_for_failure,
    repair_unavailable,
    residual_text,
)
from ..viewer.state import SpectrumKey
from ..viewer.wording import percent_text
from . import menus, window_settings
from .compare import CompareWindow
from .dialogs import ask, file_message, offer_open_anyway
from ..scene.export import save_field_mesh, save_screenshot
from .pair_window import PairWindow, open_pair_window
from .panels import (
    AnimationPanel,
    ComputePanel,
    DistancesPanel,
    JobsPanel,
    ModesPanel,
    StatusLine,
)
from .qt_dispatch import QtDispatcher
from .scene_view import SceneView
from .viewport import make_viewport

log = logging.getLogger("modalviewer")

LONG_WAIT_SECONDS = 30.0
"""Requests expected to take longer (and showing nothing meanwhile) say so when they
start."""


MIN_VIEW_SIZE = (320, 240)
"""The smallest the 3D view gets, in pixels; the window's minimum width follows."""


class ComputeError(RuntimeError):
    """A computation started from the scripting API failed; the message is for users."""


class MainWindow(QtWidgets.QMainWindow):
    """The modalviewer main window."""

    meshLoaded = QtCore.Signal(str)
    spectrumReady = QtCore.Signal(str)

    def __init__(
        self,
        force_offscreen: bool | None = None,
        cache: SpectrumCache | None = None,
        remember_settings: bool | None = None,
    ):
        super().__init__()
        self.setWindowTitle("modalviewer")
        self.setAcceptDrops(True)
        self.settings = window_settings.settings()
        self.remember_settings = (
            (not window_settings.headless())
            if remember_settings is None
            else bool(remember_settings)
        )
        self.dispatcher = QtDispatcher(self)
        self.model = ViewerModel(cache=cache, dispatch=self.dispatcher)
        self.state = self.model.state
        self.cache = self.model.cache
        self.last_error: str | None = None
        self.message_box: QtWidgets.QMessageBox | None = None  # the last one opened
        self.sliver_failure: SpectrumKey | None = None  # failed on slivers, to retry
        self.compare: CompareWindow | None = None
        self._waits: list[QtCore.QEventLoop] = []
        self._cancel_note = ""  # what Esc cancelled, said again when the next job starts

        self.viewport = make_viewport(self, force_offscreen)
        self.plotter = self.viewport.plotter
        # a usable 3D view however narrow the window: the docks keep the widths their
        # contents need, so without it a 700-pixel window left the view 45 pixels wide
        self.viewport.widget.setMinimumSize(MIN_VIEW_SIZE[0], MIN_VIEW_SIZE[1])
        self.setCentralWidget(self.viewport.widget)
        self.viewport.widget.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        self.viewport.widget.installEventFilter(self)
        self.viewport.clicked.connect(self._on_view_clicked)
        self.scene_view = SceneView(self.state, self.viewport, self)

        self.compute_panel = ComputePanel(self.state)
        self.compute_panel.computeRequested.connect(lambda: self.compute(wait=False))
        self.jobs_panel = JobsPanel(self.model.jobs)
        self.modes_panel = ModesPanel(self.state)
        self.animation_panel = AnimationPanel(self.state)
        self.distances_panel = DistancesPanel(self.state)
        self.distances_panel.showDistanceRequested.connect(lambda: self.show_distance())
        self.distances_panel.showSignatureRequested.connect(
            lambda: self.show_signature(self.state.display.signature_sample)
        )
        self._build_docks()
        menus.build_menus(self)
        self._build_status_bar()

        self.state.events.mesh.connect(self._on_mesh)
        self.state.events.spectra.connect(self.spectrumReady.emit)
        self.model.jobs.events.changed.connect(self._on_job_changed)
        self.model.jobs.events.finished.connect(self._on_job_finished)
        window_settings.restore(self)
        # preferences are written a second after they change, not only on a clean quit
        self._settings_timer = QtCore.QTimer(self)
        self._settings_timer.setSingleShot(True)
        self._settings_timer.setInterval(1000)
        self._settings_timer.timeout.connect(lambda: window_settings.save(self))
        for event in (
            self.state.events.compute_settings,
            self.state.events.style,
            self.state.events.animation,
        ):
            event.connect(lambda *_: self._settings_timer.start())

    # ================================================================== UI
    def _build_docks(self) -> None:
        area = QtCore.Qt.DockWidgetArea
        compute = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(compute)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.compute_panel)
        lay.addWidget(QtWidgets.QLabel("<b>Computations</b>"))
        lay.addWidget(self.jobs_panel)
        lay.addStretch(1)
        self._add_dock("Compute", compute, area.LeftDockWidgetArea)
        modes = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(modes)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(self.modes_panel)
        lay.addWidget(self.animation_panel)
        self._add_dock("Modes", modes, area.RightDockWidgetArea)
        self._add_dock("Distances and signatures", self.distances_panel, area.RightDockWidgetArea)

    def _add_dock(self, title: str, widget: QtWidgets.QWidget, area) -> QtWidgets.QDockWidget:
        dock = QtWidgets.QDockWidget(title, self)
        dock.setMaximumWidth(340)
        dock.setObjectName(title.replace(" ", "_"))
        scroll = QtWidgets.QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(widget)
        # wide enough for its contents (no sideways scrolling; labels wrap)
        scroll.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        needed = widget.minimumSizeHint().width() + scroll.verticalScrollBar().sizeHint().width()
        scroll.setMinimumWidth(min(340, needed + 4))
        dock.setWidget(scroll)
        self.addDockWidget(area, dock)
        return dock

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.status_line = StatusLine(self.state)
        self.status_line.setMaximumWidth(self.STATUS_LINE_WIDTH)
        bar.addPermanentWidget(self.status_line)
        self.progress = QtWidgets.QProgressBar()
        self.progress.setFixedWidth(260)
        self.progress.setRange(0, 1000)
        self.progress.hide()
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setToolTip("Cancel the running computation (Esc)")
        self.cancel_button.clicked.connect(self.cancel_computation)
        self.cancel_button.hide()
        bar.addPermanentWidget(self.progress)
        bar.addPermanentWidget(self.cancel_button)
        # the message shares the bar with the status line: while one is shown the status
        # line (elided, whole in its tooltip) gives it room; whole message on hover
        bar.messageChanged.connect(self._on_status_message)

    STATUS_LINE_WIDTH = 620
    """Widest the status line gets; :data:`STATUS_LINE_WIDTH_BESIDE_MESSAGE` while a
    temporary message is shown, which needs the room more (what is computing and why)."""
    STATUS_LINE_WIDTH_BESIDE_MESSAGE = 300

    def _on_status_message(self, text: str) -> None:
        self.statusBar().setToolTip(text)
        self.status_line.setMaximumWidth(
            self.STATUS_LINE_WIDTH_BESIDE_MESSAGE if text else self.STATUS_LINE_WIDTH
        )

    # ============================================================ messages
    def show_error(self, message: str, title: str = "modalviewer") -> None:
        """A non-blocking warning dialog with a human message; the app keeps running."""
        self.last_error = message
        log.warning("%s", message)
        self.statusBar().showMessage(message, 10000)
        if os.environ.get("MODALVIEWER_NO_DIALOGS"):
            return
        self._open_box(QtWidgets.QMessageBox.Icon.Warning, title, message)

    def show_info(self, message: str, title: str = "modalviewer") -> None:
        """A non-blocking information dialog (and the status bar)."""
        log.info("%s", message)
        self.statusBar().showMessage(message.replace("\n", " "), 20000)
        if not os.environ.get("MODALVIEWER_NO_DIALOGS"):
            self._open_box(QtWidgets.QMessageBox.Icon.Information, title, message)

    def _open_box(self, icon, title: str, message: str, action=None) -> QtWidgets.QMessageBox:
        """Open a non-blocking message box (``self.message_box``); ``action``: (label,
        callback) of a button that is the default, beside Close."""
        buttons = QtWidgets.QMessageBox.StandardButton
        box = QtWidgets.QMessageBox(icon, title, message, buttons.NoButton, self)
        if action is None:
            box.setStandardButtons(buttons.Ok)
        else:
            label, callback = action
            button = box.addButton(label, QtWidgets.QMessageBox.ButtonRole.AcceptRole)
            button.clicked.connect(callback)
            box.addButton(buttons.Close)
            box.setDefaultButton(button)  # the action the user asked for
        box.setAttribute(QtCore.Qt.WidgetAttribute.WA_DeleteOnClose)
        box.open()
        self.message_box = box
        return box

    # =========================================================== settings
    def closeEvent(self, event):  # noqa: N802
        self.state.set_animation(playing=False)
        if self.compare is not None:
            self.compare.close()
        self.model.jobs.shutdown(5.0)
        for loop in self._waits:
            loop.quit()
        window_settings.save(self)
        self.viewport.close_plotter()
        super().closeEvent(event)

    # ============================================================== keys
    def eventFilter(self, obj, event):  # noqa: N802
        """Arrow keys step modes and Space plays only while the 3D view has the focus,
        so they never steal a key from a focused slider, spin box or button."""
        if obj is self.viewport.widget and event.type() == QtCore.QEvent.Type.KeyPress:
            key = event.key()
            if key in (QtCore.Qt.Key.Key_Right, QtCore.Qt.Key.Key_Up):
                self.step_mode(+1)
                return True
            if key in (QtCore.Qt.Key.Key_Left, QtCore.Qt.Key.Key_Down):
                self.step_mode(-1)
                return True
            if key == QtCore.Qt.Key.Key_Space:
                self.toggle_animation()
                return True
        return super().eventFilter(obj, event)

    def step_mode(self, step: int) -> None:
        d = self.state.display
        operator = d.operator if d.kind == "mode" else self.modes_panel.spectrum_combo.currentData()
        if operator is None or self.state.spectrum(operator) is None:
            return
        self.state.show_mode((d.mode if d.kind == "mode" else 0) + step, operator)

    def toggle_animation(self) -> None:
        self.state.set_animation(playing=not self.state.animation.playing)

    # ============================================================= loading
    def dragEnterEvent(self, event):  # noqa: N802
        if event.mimeData().hasUrls():
            event.acceptProposedAction()

    def dropEvent(self, event):  # noqa: N802
        """A file dropped on the left half opens as the mesh; on the right half, with a
        mesh open, as the second mesh of a shape pair."""
        urls = event.mimeData().urls()
        if not urls:
            return
        path = urls[0].toLocalFile()
        x = event.position().x() if hasattr(event, "position") else event.pos().x()
        if self.state.mesh is not None and x > self.width() / 2:
            self.open_second_mesh(path, wait=False)
        else:
            self.open_mesh(path)

    def open_mesh(self, path, strict: bool = True) -> bool:
        """Load a mesh file and show it; returns False (after a message) if it failed.

        A damaged or truncated file is named with the place of the damage, and the
        dialog offers "Open anyway": what the file holds of whole records is loaded
        (``strict=False``) and the report says what was dropped."""
        path = Path(path)
        QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.WaitCursor)
        try:
            from ..io import load_mesh

            mesh = load_mesh(path, strict=strict)
        except DamagedFileError as exc:
            QtWidgets.QApplication.restoreOverrideCursor()
            return offer_open_anyway(self, path, exc) and self.open_mesh(path, strict=False)
        except MeshError as exc:  # e.g. a point cloud: the message names the file
            self.show_error(file_message(path, str(exc)), "Cannot open mesh")
            return False
        except OSError as exc:
            self.show_error(
                f"{path.name}: cannot be read ({exc.strerror or exc})", "Cannot open mesh"
            )
            return False
        finally:
            QtWidgets.QApplication.restoreOverrideCursor()
        self.set_mesh(mesh, path)
        window_settings.remember_file(self, path.resolve())
        return True

    def set_mesh(self, mesh: Mesh, path: Path | None = None) -> None:
        """Show ``mesh``; the previous mesh's spectra are dropped, its jobs cancelled."""
        if self.compare is not None:
            self.compare.close()
        self.model.set_mesh(mesh, path)

    def _on_mesh(self) -> None:
        mesh, path = self.state.mesh, self.state.mesh_path
        name = path.name if path else "mesh"
        self.setWindowTitle(f"modalviewer - {name}" if mesh is not None else "modalviewer")
        if mesh is not None:
            self.statusBar().showMessage(str(mesh.report), 15000)
        self.meshLoaded.emit(str(path) if path else "")

    # =========================================================== computing
    def compute(
        self, operator: str | None = None, k: int | None = None, wait: bool = True, then=None
    ):
        """Compute a spectrum in the background (cached on disk) and show it when ready.

        With ``wait=True`` the call returns this request's Spectrum once ready (the event
        loop keeps running meanwhile) and raises ComputeError if this request failed or
        was cancelled.  ``then`` is called with the spectrum when it arrives.
        """
        if self.state.mesh is None:
            self.show_error("Open a mesh first.")
            if wait:
                raise ComputeError("Open a mesh first.")
            return None
        changes = {}
        if operator is not None:
            changes["operator"] = operator
        if k is not None:
            changes["k"] = int(k)
        if changes:
            self.state.set_compute_settings(**changes)
        return self._run(self._request(None, None, show=True), wait, then)

    def _request(self, operator, k, show) -> Job | None:
        try:
            job = self.model.request_spectrum(operator, k, show=show)
        except ComputeRefused as exc:
            self.show_error(str(exc), "Computation too large")
            return None
        note = self._long_wait_note(job)
        if note:
            self.statusBar().showMessage(f"{job.description}: {note}.", 20000)
        return job

    def _long_wait_note(self, job: Job) -> str:
        """ "this will take about ..." for a request expected to take long with nothing on
        screen meanwhile (a click on the surface starts one for the vibration distance);
        "" otherwise (with a preview the wait is for its exact spectrum, behind a
        picture)."""
        if job.done or getattr(job, "preview_job", None) is not None:
            return ""
        seconds, _ = cost_estimate(job.spectrum_key, self.state.mesh.n_vertices)
        if seconds <= LONG_WAIT_SECONDS:
            return ""
        about = f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min"
        faster = "" if job.spectrum_key.coarse else "; Coarse-to-fine is much faster"
        return f"this will take about {about} (Esc cancels{faster})"

    def _run(self, job: Job | None, wait: bool, then=None):
        if job is None:
            if wait:
                raise ComputeError(self.last_error or "the computation was refused")
            return None
        if then is not None:
            job.then(lambda j: then(j.result[0]) if j.status == DONE else None)
        if not wait:
            return None
        self.wait_for(job)
        if job.status != DONE:
            raise ComputeError(job.error or job.status)
        return job.result[0]

    def wait_for(self, job: Job) -> Job:
        """Run the event loop until ``job`` (and only it) has ended."""
        if job.done:
            return job
        loop = QtCore.QEventLoop()
        job.then(lambda _j: loop.quit())
        self._waits.append(loop)
        try:
            loop.exec()
        finally:
            self._waits.remove(loop)
        return job

    def cancel_computation(self) -> None:
        """Cancel the running computation, and the exact spectrum waiting behind its
        preview; other queued requests keep their turn (the status bar says how many, and
        that Ctrl+Shift+Esc cancels them too, also when the next one starts)."""
        if self.model.jobs.running is None:
            self.statusBar().showMessage("No computation running.", 3000)
            return
        self.model.cancel_running()
        left = {
            getattr(job, "spectrum_key", None) or job.key
            for job in self.model.jobs.jobs
            if not job.done and not job.cancel_requested
        }
        plural = "s" if len(left) > 1 else ""
        self._cancel_note = (
            f"Cancelled; {len(left)} more request{plural} queued (Ctrl+Shift+Esc cancels all)"
            if left
            else ""
        )
        self.statusBar().showMessage(self._cancel_note or "Cancelling...", 5000)

    def cancel_all(self) -> None:
        self.model.jobs.cancel_all()

    def _on_job_changed(self, job: Job) -> None:
        running = self.model.jobs.running
        self.progress.setVisible(running is not None)
        self.cancel_button.setVisible(running is not None)
        if running is not None:
            self.progress.setValue(int(1000 * running.fraction))
            queued = len(self.model.jobs.jobs) - 1
            more = f" (+{queued} queued)" if queued else ""
            stage = running.stage if len(running.stage) <= 20 else running.stage[:19] + "…"
            self.progress.setFormat(f"{stage} %p %{more}")  # as in the Computations list
            self.progress.setToolTip(f"{running.description}: {running.stage}")
            if job is running and job.stage == "starting":
                self.statusBar().showMessage(self._starting_message(job))

    def _starting_message(self, job: Job) -> str:
        """ "Computing ...", after the preview shown before it (with its estimated error)
        or with the reason a big request gets no preview; after an Esc that left other
        requests queued, first what it cancelled."""
        key = getattr(job, "spectrum_key", None)
        preview = getattr(job, "preview_job", False)
        text = f"Computing {job.description}..."
        if key is not None and preview is None:
            note = self.model.no_preview_note(key)
            if note:
                text = f"Computing {job.description}; {note}."
        elif preview and preview.status == DONE:
            error = percent_text(preview.result[0].estimated_error)
            text = f"Preview shown (estimated error {error}); computing the exact spectrum..."
        note, self._cancel_note = self._cancel_note, ""
        return f"{note}. {text}" if note else text

    def _on_job_finished(self, job: Job) -> None:
        result = job.result
        spectrum = isinstance(result, tuple) and result and isinstance(result[0], Spectrum)
        if job.status == DONE and not spectrum:
            # a repair (whose own callback then shows its report) or other work
            self.statusBar().showMessage(f"{job.description}: done in {job.seconds:.1f} s.", 15000)
        elif job.status == DONE:
            spec = result[0]
            quality = (
                f"estimated eigenvalue error {percent_text(spec.estimated_error)}"
                if spec.is_preview
                else residual_text(spec)
            )
            self.statusBar().showMessage(
                f"{job.description} in {job.seconds:.1f} s; {quality}.", 15000
            )
        elif job.status == "failed":
            log.error("computation failed: %s\n%s", job.error, job.details)
            key = getattr(job, "spectrum_key", None)
            mesh = self.state.mesh
            if (
                key is not None
                and mesh is not None
                and job.owner == mesh.hash
                and repair_for_failure(job.error) == "fix_slivers"
            ):
                self._offer_sliver_fix(job, key)
            else:
                self.show_error(f"The computation failed: {job.error}", "Computation failed")
        elif job.status == "cancelled":
            self.statusBar().showMessage(f"{job.description}: {job.error or 'cancelled'}.", 5000)

    # =============================================================== modes
    def show_mode(self, index: int, operator: str | None = None) -> None:
        """Colour the surface by mode ``index`` (of ``operator``, default: the spectrum
        shown or last computed)."""
        op = operator or self.current_operator
        if op is None or self.state.spectrum(op) is None:
            return
        self.state.show_mode(index, op)

    def _show_current_mode(self) -> None:
        """Back to the mode last shown (M), or the first non-zero mode."""
        d = self.state.display
        op = d.operator if self.state.spectrum(d.operator) is not None else self.current_operator
        if op is not None:
            mode = d.mode if op == d.operator else self.state.first_nonzero_mode(op)
            self.show_mode(mode, op)

    def set_animating(self, on: bool) -> None:
        self.state.set_animation(playing=on)

    def animation_frame(self, phase: float) -> float:
        """Move the surface to the given phase (radians); returns the app's time in s."""
        return self.scene_view.animation_frame(phase)

    # ============================================================ distances
    def _on_view_clicked(self, x: float, y: float) -> None:
        scene = self.scene
        if scene is None:
            return
        vertex = scene.vertex_at_display(x, y)
        if vertex is not None:
            self.pick_vertex(vertex)

    def pick_file_vertex(self, number: int) -> None:
        """Pick vertex ``number`` of the mesh file (the number the viewer shows, as
        ``distance --vertex`` takes it); an error message for one no face uses."""
        if self.state.mesh is None:
            return
        try:
            index = self.state.mesh.mesh_vertex(number)
        except ValueError as exc:
            self.show_error(str(exc))
            return
        self.pick_vertex(index)

    def pick_vertex(self, index: int) -> None:
        """Pick mesh vertex ``index`` (as a click on it does): marker and distance map.
        ``index`` is the loaded mesh's (compact) index; see :meth:`pick_file_vertex`."""
        if self.state.mesh is None:
            return
        try:
            self.state.set_pick(index)
        except ValueError as exc:
            self.show_error(str(exc))
            return
        self.show_distance()

    def show_distance(
        self, kind: str | None = None, display: str | None = None, threshold: float | None = None
    ) -> np.ndarray | None:
        """Distance map from the picked vertex.

        kind: "vibration" | "feature" | "hks"; display: "continuous" | "threshold";
        threshold: as a fraction of the largest distance (0..1).  A missing spectrum is
        computed in the background; the map appears when it is ready (unless the
        display was changed meanwhile).
        """
        changes = {}
        if kind is not None:
            changes["distance_kind"] = kind
        if display is not None:
            changes["distance_display"] = display
        if threshold is not None:
            changes["threshold"] = float(threshold)
        if changes:
            self.state.set_display(**changes)
        if self.state.mesh is None:
            return None
        if self.state.picked is None:
            self.statusBar().showMessage("Click the surface to pick a vertex first.", 5000)
            return None
        kind = self.state.display.distance_kind
        operator = operator_for_distance(kind)
        if self.state.spectrum(operator) is None:
            job = self._request(operator, None, show=False)
            if job is not None:
                before = self.state.display

                def show_when_ready(j: Job) -> None:
                    if j.status == DONE and self.state.display == before:
                        self.state.set_display(kind="distance")

                preview = getattr(job, "preview_job", None)
                if preview is not None:  # the map from the preview first
                    preview.then(show_when_ready)
                job.then(show_when_ready)
                note = self._long_wait_note(job)
                self.statusBar().showMessage(
                    f"Computing the spectrum for the {DISTANCE_KINDS[kind].lower()}"
                    + (f"; {note}." if note else "...")
                )
            return None
        self.state.set_display(kind="distance")
        return self.state.derived.distance_map()

    def distance_map(self, kind: str) -> np.ndarray | None:
        """Distance of ``kind`` from the picked vertex, or None if its spectrum is missing."""
        return self.state.derived.distance_map(kind)

    def set_threshold(self, fraction: float) -> float:
        """Move the threshold (fraction of the largest distance); returns the app's time in s."""
        import time

        started = time.perf_counter()
        self.state.set_display(threshold=float(fraction))
        return time.perf_counter() - started

    def show_signature(self, sample: int) -> None:
        """Colour by the signature at scale sample ``sample`` of the distance kind's spectrum."""
        operator = operator_for_distance(self.state.display.distance_kind)
        if not self.state.derived.has_signatures(operator):
            self.statusBar().showMessage(
                f"Compute the {OPERATOR_INFO[operator].label} spectrum first (with non-zero "
                "modes).",
                5000,
            )
            return
        self.state.set_display(kind="signature", signature_sample=int(sample))

    def show_curvature(self) -> None:
        if self.state.mesh is not None:
            self.state.set_display(kind="curvature")

    # ========================================================= shape pair
    def open_second_mesh(self, path, wait: bool = True, k: int | None = None) -> PairWindow:
        """Open ``path`` as mesh B beside this window's mesh A in a shape pair window: a
        click on one mesh shows the distance between shapes on the other.  With ``wait``
        the call returns once both spectra are in (``k`` modes each, default 100)."""
        return open_pair_window(self, path, wait=wait, k=k)

    # ========================================================= comparison
    def open_comparison(self, items: list[str], wait: bool = True) -> CompareWindow | None:
        """Linked side-by-side views of two or three operators or distance kinds.

        A script (``wait=True``) computes missing spectra and returns the window once
        they are ready; from the menu (``wait=False``) the user is asked first.  The
        main window's display is never changed.
        """
        if self.state.mesh is None:
            self.show_error("Open a mesh first.")
            return None
        needed = [operator_for_distance(i) if i in DISTANCE_KINDS else i for i in items]
        missing = [op for op in dict.fromkeys(needed) if self.state.spectrum(op) is None]
        if missing and not wait:
            k = self.state.compute_settings.k
            n = self.state.mesh.n_vertices
            settings_ = self.state.compute_settings
            total = sum(cost_estimate(settings_.key(op), n)[0] for op in missing)
            names = ", ".join(OPERATOR_INFO[op].label for op in missing)
            question = (
                f"The comparison needs {names} ({k} modes each; at least "
                f"{max(total, 1):.0f} s on an idle machine). "
                "Compute now? The main view is not changed."
            )
            if not ask(self, "Compare", question, default_yes=True):  # asked for by the menu
                return None
        jobs = [self._request(op, None, show=False) for op in missing]
        if any(job is None for job in jobs):
            return None
        if missing and not wait:
            pending = {job.id for job in jobs}
            items = list(items)

            def open_when_ready(j: Job) -> None:
                pending.discard(j.id)
                if j.status != DONE:
                    pending.clear()
                elif not pending and all(x.status == DONE for x in jobs):
                    self._show_comparison(items)

            for job in jobs:
                job.then(open_when_ready)
            return None
        for job in jobs:
            self.wait_for(job)
            if job.status != DONE:
                raise ComputeError(job.error or job.status)
        return self._show_comparison(items)

    def _show_comparison(self, items) -> CompareWindow:
        if self.compare is not None:
            self.compare.close()
        self.compare = CompareWindow(self, items)
        self.compare.show()
        self.compare.refresh()
        return self.compare

    # ============================================================== export
    def export_screenshot(
        self, path, scale: int = 1, transparent: bool = False, colorbar: bool | None = None
    ) -> Path:
        """Save the view as PNG (atomically); returns the path.  ``colorbar``: include
        the colour bar and legend (None: as on screen)."""
        if colorbar is not None:
            self.state.set_colorbar(colorbar)
        return save_screenshot(
            self.viewport, Path(path), scale=scale, transparent=transparent, scene=self.scene
        )

    def current_field(self) -> tuple[str, np.ndarray] | None:
        """(name, per-vertex values) of what the surface shows, or None without a mesh."""
        scene = self.scene
        if scene is None:
            return None
        return (scene.field_name or "field"), np.array(scene.surface.point_data["field"])

    def export_field(self, path) -> Path:
        field = self.current_field()
        if field is None:
            raise ValueError("nothing to export: open a mesh first")
        name, values = field
        return save_field_mesh(Path(path), self.state.mesh, {name: values})

    # ============================================================ repairs
    def repair_mesh(self, name: str, wait: bool = True) -> Mesh | None:
        """Apply repair ``name`` ("fix_slivers", "largest_component") to the loaded mesh in
        the background; the repaired mesh replaces it and its report is shown."""
        try:
            job = self.model.repair(name)
        except ValueError as exc:
            self.show_error(str(exc))
            return None
        job.then(self._on_repaired)
        if not wait:
            return None
        self.wait_for(job)
        if job.status != DONE:
            raise ComputeError(job.error or job.status)
        return job.result

    def _offer_sliver_fix(self, job: Job, key: SpectrumKey) -> None:
        """The failure of ``key`` on sliver triangles, with a "Fix slivers and retry"
        button (the default); without dialogs, :meth:`fix_slivers_and_retry` does it."""
        self.sliver_failure = key
        message = f"The computation failed: {job.error}"
        self.last_error = message
        log.warning("%s", message)
        self.statusBar().showMessage(message, 10000)
        if os.environ.get("MODALVIEWER_NO_DIALOGS"):
            return
        self._open_box(
            QtWidgets.QMessageBox.Icon.Warning,
            "Computation failed",
            f"{message}.\n\nFix slivers and retry: repair the mesh (Mesh > Fix slivers), "
            f"then compute {key.describe()} again.",
            ("Fix slivers and retry", lambda: self.fix_slivers_and_retry(key)),
        )

    def fix_slivers_and_retry(self, key: SpectrumKey | None = None, wait: bool = False):
        """Fix the loaded mesh's slivers (as Mesh > Fix slivers), show the repair's report
        and request again the spectrum ``key`` (default: the last one whose factorisation
        failed on slivers).  Without pymeshlab a dialog says how to install it.  Returns
        the repair job (None if none started); with ``wait`` also waits for the spectrum
        and returns it."""
        key = key or self.sliver_failure
        if key is None:
            self.statusBar().showMessage("No computation failed on sliver triangles.", 5000)
            return None
        missing = repair_unavailable("fix_slivers")
        if missing:
            self.show_error(missing, "Fix slivers")
            return None
        try:
            job = self.model.repair("fix_slivers")
        except ValueError as exc:
            self.show_error(str(exc))
            return None
        retried: list[Job | None] = []

        def retry(j: Job) -> None:
            # a failed repair is shown as any failed job (_on_job_finished)
            if j.status != DONE or self.state.mesh is not j.result:
                return  # failed, cancelled, or another mesh was opened meanwhile
            self.sliver_failure = None
            self.show_info(
                f"{j.result.report}\n\nComputing {key.describe()} again...", "Slivers fixed"
            )
            self.state.set_compute_settings(operator=key.operator, k=key.k)
            retried.append(self._request(key.operator, key.k, show=True))

        job.then(retry)
        if not wait:
            return job
        self.wait_for(job)
        if job.status != DONE or not retried:
            raise ComputeError(job.error or job.status)
        return self._run(retried[0], wait=True)

    def _on_repaired(self, job: Job) -> None:
        if job.status == DONE:
            self.statusBar().showMessage(str(job.result.report), 20000)
        elif job.status == "failed":
            self.show_error(f"{job.description} failed: {job.error}", "Repair failed")

    # =============================================================== cache
    def clear_cache(self) -> int:
        """Delete every cached spectrum; returns the bytes freed."""
        size = self.cache.clear()
        self.statusBar().showMessage(f"Cache cleared: {size / 2**20:.0f} MB freed.", 8000)
        return size

    # ============================================================ sessions
    def save_session(self, path) -> Path:
        """Write the session (mesh, spectra, display, pick, camera) to a JSON file."""
        from ..viewer.session import save_session

        self.state.camera = self.scene_view.current_camera()
        return save_session(self.state, path)

    def open_session(self, path, wait: bool = True) -> list[str]:
        """Restore a session; returns the notes on what could not be restored as saved.

        With ``wait`` the call returns once every spectrum is loaded or recomputed and
        the picture is drawn."""
        from ..viewer.session import SessionError, restore_session

        try:
            restored = restore_session(self.model, path)
        except (SessionError, MeshError, OSError) as exc:
            self.show_error(f"Cannot open the session: {exc}", "Cannot open session")
            return [str(exc)]
        if self.state.mesh_path is not None and self.remember_settings:
            window_settings.remember_file(self, Path(self.state.mesh_path).resolve())
        if wait:
            for job in restored.jobs:
                self.wait_for(job)
        if restored.notes:
            self.statusBar().showMessage("; ".join(restored.notes), 15000)
        return restored.notes

    # ==================================================== read-only views
    @property
    def mesh(self) -> Mesh | None:
        return self.state.mesh

    @property
    def scene(self):
        return self.scene_view.scene

    @property
    def spectra(self) -> dict[str, Spectrum]:
        """The latest spectrum of each computed operator (a copy; the state owns them)."""
        return {op: self.state.spectrum(op) for op in self.state.operators_computed()}

    @property
    def current_operator(self) -> str | None:
        """The operator of the mode shown, else the one chosen in the Modes panel."""
        d = self.state.display
        if d.kind == "mode":
            return d.operator
        return self.modes_panel.spectrum_combo.currentData()

    @property
    def display(self) -> str:
        return self.state.display.kind

    @property
    def picked(self) -> int | None:
        return self.state.picked

    @property
    def last_distance(self) -> np.ndarray | None:
        return self.state.derived.distance_map() if self.state.display.kind == "distance" else None

    @property
    def frame_times(self) -> list[float]:
        return self.scene_view.frame_times

    @property
    def running_job(self) -> Job | None:
        return self.model.jobs.running

    @property
    def busy(self) -> bool:
        return self.model.jobs.busy
