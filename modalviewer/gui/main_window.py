"""The main window: wires a :class:`~modalviewer.viewer.Viewer` to the docks, the 3D view
and the menus.

The viewer (``win.viewer``) owns the state, the jobs and the cache; panels and the
scene observe its state, and the window shows its messages.  The window's scripting
methods delegate to the viewer, so a script drives the window as it drives a
:class:`~modalviewer.viewer.Viewer` (docs/viewer-guide.md shows one).
"""

from __future__ import annotations

import logging
import os
import time
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from contextlib import contextmanager
from functools import partial
from operator import attrgetter
from pathlib import Path

from qtpy import QtCore, QtGui, QtWidgets

from ..core.cache import SpectrumCache
from ..core.mesh import Mesh, MeshError
from ..core.operators import OPERATOR_INFO
from ..readers import DamagedFileError
from ..viewer.jobs import Job
from ..viewer.state import SpectrumKey
from ..viewer.viewer import ComputeError, Viewer
from ..viewer.wording import seconds_text
from . import menus, window_settings
from .application import ensure_application
from .compare import CompareWindow
from .dialogs import ask, file_message, offer_open_anyway
from .docks import build_docks
from .pair_window import PairWindow, open_pair_window
from .panels.animation import AnimationPanel
from .panels.common import follow
from .panels.compute import ComputePanel
from .panels.distances import DistancesPanel
from .panels.jobs import JobsPanel
from .panels.modes import ModesPanel
from .qt_dispatch import QtDispatcher
from .scene_view import SceneView
from .status_bar import StatusBarWidgets
from .viewport import make_viewport

__all__ = ["ComputeError", "MainWindow"]

log = logging.getLogger("modalviewer")

MIN_VIEW_SIZE = (320, 240)
"""The smallest the 3D view gets, in pixels; the window's minimum width follows."""

READING_WAIT_S = 0.2
"""A mesh file read within this many seconds opens without running the event loop
(:meth:`MainWindow._read_mesh`): the bundled meshes and most scans."""

READING_DIALOG_S = 0.8
"""A reading that lasts this many seconds shows the dialog with Cancel."""

FROM_VIEWER = frozenset(
    "compute cancel_computation set_mesh show_mode step_mode show_distance distance_map "
    "set_threshold show_signature show_curvature export_screenshot current_field "
    "export_field fix_slivers_and_retry clear_cache save_session spectra picked "
    "sliver_failure last_error".split()
)
"""What the window passes on to its :class:`~modalviewer.viewer.Viewer` unchanged, so a
script drives the window as it drives a viewer."""

REPORTED = frozenset({"pick_vertex", "repair_mesh"})
"""The viewer's methods the window passes on with a bad argument's ValueError shown to
the user instead of raised."""

VIEWS = {
    "cache": "viewer.cache",
    "plotter": "viewport.plotter",
    "status_line": "status_widgets.status_line",
    "mesh": "state.mesh",
    "scene": "scene_view.scene",
    "running_job": "viewer.jobs.running",
    "busy": "viewer.jobs.busy",
    "cancel_all": "viewer.jobs.cancel_all",
    "animation_frame": "scene_view.drawing.animation_frame",
}
"""Parts of the window's parts, by name: read-only values and two methods."""


@contextmanager
def _shortcuts_off(window):
    """Disable ``window``'s actions and shortcuts that have a key for the duration, then
    give each back the state it had: keys pressed meanwhile are dropped, all of them.
    Dialogs keep theirs (Esc cancels the reading; a closed one may be deleted meanwhile)."""
    keyed = [a for a in window.findChildren(QtGui.QAction) if not a.shortcut().isEmpty()]
    shortcuts = window.findChildren(QtGui.QShortcut)
    keyed += [s for s in shortcuts if not isinstance(s.parent(), QtWidgets.QDialog)]
    enabled = [item.isEnabled() for item in keyed]
    for item in keyed:
        item.setEnabled(False)
    try:
        yield
    finally:
        for item, on in zip(keyed, enabled, strict=True):
            item.setEnabled(on)


class MainWindow(QtWidgets.QMainWindow):
    """The modalviewer main window, showing ``viewer`` (a new :class:`Viewer` if None)."""

    def __init__(
        self,
        viewer: Viewer | None = None,
        force_offscreen: bool | None = None,
        cache: SpectrumCache | None = None,
        remember_settings: bool | None = None,
    ):
        ensure_application()
        super().__init__()
        self.setWindowTitle("modalviewer")
        self.setAcceptDrops(True)
        self.settings = window_settings.settings()
        self.remember_settings = (
            (not window_settings.headless())
            if remember_settings is None
            else bool(remember_settings)
        )
        self.viewer = viewer if viewer is not None else Viewer(cache=cache)
        self.dispatcher = QtDispatcher(self)
        self._waits: list[QtCore.QEventLoop] = []
        self.viewer.use_event_loop(self.dispatcher, self.wait_for)
        self.state = self.viewer.state
        self.message_box: QtWidgets.QMessageBox | None = None  # the last one opened
        self.compare: CompareWindow | None = None

        self.viewport = make_viewport(self, force_offscreen)
        # a usable 3D view however narrow the window: the docks keep the widths their
        # contents need, so without it a 700-pixel window left the view 45 pixels wide
        self.viewport.widget.setMinimumSize(*MIN_VIEW_SIZE)
        self.setCentralWidget(self.viewport.widget)
        self.viewport.widget.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
        self.viewport.widget.installEventFilter(self)
        self.viewport.clicked.connect(self._on_view_clicked)
        self.scene_view = SceneView(self.state, self.viewport, self)
        self.viewer.attach_picture(self.scene_view)

        self.compute_panel = ComputePanel(self.viewer)
        self.jobs_panel = JobsPanel(self.viewer.jobs, self.state)
        self.modes_panel = ModesPanel(self.viewer)
        self.animation_panel = AnimationPanel(self.state)
        self.distances_panel = DistancesPanel(self.viewer)
        build_docks(self)
        menus.build_menus(self)
        self.status_widgets = StatusBarWidgets(
            self.statusBar(), self.state, self.viewer.jobs, self.cancel_computation
        )

        self.state.events.mesh.connect(self._on_mesh)
        messages = self.viewer.events
        messages.status.connect(lambda text, msec: self.statusBar().showMessage(text, msec))
        messages.error.connect(self._show_error_box)
        messages.info.connect(self._show_info_box)
        messages.sliver_failure.connect(self._offer_sliver_fix)
        window_settings.restore(self)
        # preferences are written a second after they change, not only on a clean quit
        self._settings_timer = QtCore.QTimer(self, singleShot=True, interval=1000)
        self._settings_timer.timeout.connect(lambda: window_settings.save(self))
        save_soon = lambda *_: self._settings_timer.start()  # noqa: E731
        follow(self.state, save_soon, "compute_settings", "style", "animation")
        if self.state.mesh is not None:  # a viewer already in use: show what it shows
            self.scene_view.drawing.sync()
            self._on_mesh()

    # ============================================================ messages
    def show_error(self, message: str, title: str = "modalviewer") -> None:
        """A non-blocking warning dialog with a human message (the viewer's
        ``last_error``); the app keeps running."""
        self.viewer.report_error(message, title)

    def _show_error_box(self, title: str, message: str) -> None:
        self.statusBar().showMessage(message, 10000)
        self._open_box(QtWidgets.QMessageBox.Icon.Warning, title, message)

    def _show_info_box(self, title: str, message: str) -> None:
        log.info("%s", message)
        self.statusBar().showMessage(message.replace("\n", " "), 20000)
        self._open_box(QtWidgets.QMessageBox.Icon.Information, title, message)

    def _open_box(self, icon, title: str, message: str, action=None) -> None:
        """Open a non-blocking message box (``self.message_box``), unless
        MODALVIEWER_NO_DIALOGS is set; ``action``: (label, callback) of a button that is
        the default, beside Close."""
        if os.environ.get("MODALVIEWER_NO_DIALOGS"):
            return
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

    # =========================================================== settings
    def closeEvent(self, event):  # noqa: N802
        self.state.animation.playing = False
        if self.compare is not None:
            self.compare.close()
        self.viewer.jobs.shutdown(5.0)
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
            key = QtCore.Qt.Key
            step = {key.Key_Right: +1, key.Key_Up: +1, key.Key_Left: -1, key.Key_Down: -1}
            if event.key() in step:
                self.step_mode(step[event.key()])
                return True
            if event.key() == key.Key_Space:
                self.toggle_animation()
                return True
        return super().eventFilter(obj, event)

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
        if self.state.mesh is not None and event.position().x() > self.width() / 2:
            self.open_second_mesh(path, wait=False)
        else:  # after the drop has ended: reading runs an event loop of its own
            QtCore.QTimer.singleShot(0, lambda: self.open_mesh(path))

    def open_mesh(self, path, strict: bool = True) -> bool:
        """Load a mesh file (:meth:`read_mesh_file`) and show it; returns False (after a
        message) if it failed or was cancelled."""
        path = Path(path)
        mesh = self.read_mesh_file(path, strict)
        if mesh is None:
            return False
        # the scene is built here, on the window's thread (VTK's objects belong to it)
        QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.WaitCursor)
        try:
            self.viewer.set_mesh(mesh, path)
        finally:
            QtWidgets.QApplication.restoreOverrideCursor()
        window_settings.remember_file(self, path.resolve())
        return True

    def read_mesh_file(self, path, strict: bool = True) -> Mesh | None:
        """The mesh of the file ``path`` (read by :meth:`_read_mesh`), or None (after a
        message) if it failed or was cancelled.  A damaged file is named with the place
        of the damage, and the dialog offers "Open anyway" (``strict=False``: the whole
        records are loaded and the report says what was dropped)."""
        path = Path(path)
        try:
            mesh = self._read_mesh(path, strict)
        except DamagedFileError as exc:
            if offer_open_anyway(self, path, exc):
                return self.read_mesh_file(path, strict=False)
            return None
        except MeshError as exc:  # e.g. a point cloud: the message names the file
            self.show_error(file_message(path, str(exc)), "Cannot open mesh")
            return None
        except OSError as exc:
            self.show_error(
                f"{path.name}: cannot be read ({exc.strerror or exc})", "Cannot open mesh"
            )
            return None
        if mesh is None:
            self.statusBar().showMessage(f"Opening {path.name} was cancelled", 8000)
        return mesh

    def _read_mesh(self, path: Path, strict: bool) -> Mesh | None:
        """:func:`modalviewer.load_mesh` of ``path`` in a worker thread, so the window
        keeps drawing; after :data:`READING_DIALOG_S` a modal dialog with Cancel.
        Returns the mesh, None if cancelled (the parser cannot be stopped: its mesh is
        dropped), or raises what ``load_mesh`` raises.  Shortcuts are off meanwhile
        (:func:`_shortcuts_off`), so no key applies to the old mesh or queues for the
        new one."""
        from ..core.robust import negative_cotan_weights
        from ..io import load_mesh

        started = time.monotonic()
        pool = ThreadPoolExecutor(1, thread_name_prefix="mesh-reader")

        def read():
            mesh = load_mesh(path, strict=strict)
            negative_cotan_weights(mesh)  # counted here, for the Compute panel's note
            return mesh

        future = pool.submit(read)
        pool.shutdown(wait=False)
        try:
            return future.result(timeout=READING_WAIT_S)  # small files: no dialog at all
        except FutureTimeout:
            pass
        try:
            size = f" ({path.stat().st_size / 2**20:.0f} MB)"
        except OSError:
            size = ""
        dialog = QtWidgets.QProgressDialog(
            f"Opening {path.name}{size}...", "Cancel", 0, 0, self, windowTitle="Opening mesh"
        )
        dialog.setWindowModality(QtCore.Qt.WindowModality.WindowModal)
        loop = QtCore.QEventLoop()
        future.add_done_callback(lambda _future: self.dispatcher(loop.quit))
        dialog.canceled.connect(loop.quit)
        # shown by hand: QProgressDialog's own delay restarts at each value
        wait_ms = int(1000 * (READING_DIALOG_S - (time.monotonic() - started)))
        QtCore.QTimer.singleShot(
            max(wait_ms, 0), dialog, lambda: loop.isRunning() and dialog.show()
        )
        with _shortcuts_off(self):
            loop.exec()
        cancelled = not future.done()
        dialog.reset()
        dialog.deleteLater()
        return None if cancelled else future.result()

    def _on_mesh(self) -> None:
        if self.compare is not None:
            self.compare.close()
        path = self.state.mesh_path
        name = path.name if path else "mesh"
        self.setWindowTitle(f"modalviewer - {name}" if self.state.mesh else "modalviewer")

    # ================================================ scripting (the Viewer)
    def __getattr__(self, name: str):
        """The viewer's scripting methods and values (:data:`FROM_VIEWER`,
        :data:`REPORTED`) and the parts' values (:data:`VIEWS`)."""
        if name in FROM_VIEWER:
            return getattr(self.viewer, name)
        if name in REPORTED:
            return partial(self._reporting, getattr(self.viewer, name))
        if name in VIEWS:
            return attrgetter(VIEWS[name])(self)
        raise AttributeError(f"'MainWindow' object has no attribute {name!r}")

    def _reporting(self, method, *args, **kwargs):
        try:
            return method(*args, **kwargs)
        except ValueError as exc:
            self.show_error(str(exc))
            return None

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

    def toggle_animation(self) -> None:
        self.state.animation.playing = not self.state.animation.playing

    def _on_view_clicked(self, x: float, y: float) -> None:
        scene = self.scene
        vertex = scene.vertex_at_display(x, y) if scene is not None else None
        if vertex is not None:  # a vertex of the drawn (solver's) mesh: the input's number
            self.pick_vertex(self.viewer.state.mesh.file_vertex(vertex))

    # ========================================================= shape pair
    def open_second_mesh(self, path, wait: bool = True, k: int | None = None) -> PairWindow:
        """Open ``path`` as mesh B beside this window's mesh A in a shape pair window: a
        click on one mesh shows the distance between shapes on the other.  With ``wait``
        the call returns once both spectra are in (``k`` modes each, by default
        :func:`~modalviewer.core.operators.default_k` of the smaller mesh)."""
        return open_pair_window(self, path, wait=wait, k=k)

    # ========================================================= comparison
    def open_comparison(self, items: list[str], wait: bool = True) -> CompareWindow | None:
        """Linked side-by-side views of two or three operators or distance kinds; never
        changes the main window's display.  With ``wait=True`` (scripts) missing spectra
        are computed and the window returned once they are in; from the menu the user is
        asked first."""
        if self.state.mesh is None:
            self.show_error("Open a mesh first.")
            return None
        missing = self.viewer.missing_for(items)
        if missing and not wait:
            names = ", ".join(OPERATOR_INFO[op].label for op in missing)
            seconds = self.viewer.comparison_cost(missing)
            about = "" if seconds is None else f"; about {seconds_text(max(seconds, 1.0))}"
            question = (
                f"The comparison needs {names} ({self.state.compute_settings.k} modes "
                f"each{about}). Compute now? The main view is not changed."
            )
            if not ask(self, "Compare", question, default_yes=True):
                return None
        items = list(items)
        if not wait:
            self.viewer.prepare_comparison(
                items, wait=False, then=lambda: self._show_comparison(items)
            )
            return None
        self.viewer.prepare_comparison(items, wait=True)
        return self._show_comparison(items)

    def _show_comparison(self, items) -> CompareWindow:
        if self.compare is not None:
            self.compare.close()
        self.compare = CompareWindow(self, items)
        self.compare.show()
        self.compare.refresh()
        return self.compare

    def _offer_sliver_fix(self, key: SpectrumKey, message: str) -> None:
        """A failure on sliver triangles, with a "Fix slivers and retry" button (the
        default)."""
        self.statusBar().showMessage(message, 10000)
        self._open_box(
            QtWidgets.QMessageBox.Icon.Warning,
            "Computation failed",
            f"{message}.\n\nFix slivers and retry: repair the mesh (Mesh > Fix slivers), "
            f"then compute {key.describe()} again.",
            ("Fix slivers and retry", lambda: self.viewer.fix_slivers_and_retry(key)),
        )

    # ============================================================ sessions
    def open_session(self, path, wait: bool = True) -> list[str]:
        """Restore a session (:meth:`Viewer.open_session
        <modalviewer.viewer.Viewer.open_session>`); a file that cannot be restored is
        reported and its message returned as the only note."""
        from ..viewer.session import SessionError

        try:
            notes = self.viewer.open_session(path, wait)
        except (SessionError, MeshError, OSError) as exc:
            self.show_error(f"Cannot open the session: {exc}", "Cannot open session")
            return [str(exc)]
        if self.state.mesh_path is not None and self.remember_settings:
            window_settings.remember_file(self, Path(self.state.mesh_path).resolve())
        if notes:  # in a box of their own: the status bar's line is soon another's
            self._show_info_box("Session restored with changes", "\n".join(notes))
        return notes
