"""The main window: docks for computing, browsing modes and distances; menus; scripting API.

Scripting interface (what the matching clicks do)::

    win.open_mesh(path); win.compute("shells", k=50, wait=True); win.show_mode(7)
    win.pick_vertex(123); win.show_distance("vibration", display="threshold", threshold=0.2)
    win.export_screenshot("fig.png", scale=2, transparent=True)
"""

from __future__ import annotations

import logging
import os
import time
from pathlib import Path

import numpy as np
from qtpy import QtCore, QtGui, QtWidgets

from ..coarsen import COARSE_FRACTION, decimated_copy
from ..core.cache import SpectrumCache
from ..core.coarse import estimate_cost, transfer_spectrum
from ..core.curvature import total_curvature
from ..core.eigen import Cancelled
from ..core.laplacian import vertex_normals
from ..core.mesh import Mesh, MeshError
from ..core.pipeline import compute_spectrum
from ..core.signatures import SignatureTable, signature
from ..core.spectrum import Spectrum, save_spectrum
from ..io import SUPPORTED_EXTENSIONS, load_mesh
from .compare import CompareWindow
from .export import save_field_mesh, save_screenshot
from .plots import LinePlot
from .scene import MeshScene
from .viewport import make_viewport
from .worker import Job, compute_in_process

log = logging.getLogger("modalviewer")

OPERATOR_LABELS = {
    "laplacian": "Laplacian (cotan)",
    "modified_dirichlet": "Modified Dirichlet E_D^N",
    "shells": "Discrete Shells (3D vibrations)",
    "shells_normal": "Discrete Shells, normal variations",
}
DISTANCE_OPERATOR = {"vibration": "shells", "feature": "modified_dirichlet", "hks": "laplacian"}
DISTANCE_LABELS = {
    "vibration": "Vibration distance",
    "feature": "Feature distance",
    "hks": "Heat kernel distance",
}
ASSETS = Path(__file__).resolve().parents[2] / "assets"
DEFAULT_MESH = ASSETS / "spot.obj"
SCREENSHOTS = Path(__file__).resolve().parents[2] / "screenshots"
PROCESS_THRESHOLD = 20000
"""Problems with at least this many unknowns are computed in a separate process."""


def _physical_memory() -> int:
    """Bytes of physical memory, or 0 if unknown."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 0


def default_k(n_vertices: int) -> int:
    """A mode count suited to the mesh: 100 for most meshes, fewer for tiny ones."""
    return int(max(2, min(100, n_vertices // 4)))


def settings() -> QtCore.QSettings:
    path = os.environ.get("MODALVIEWER_SETTINGS")
    if path:
        return QtCore.QSettings(path, QtCore.QSettings.Format.IniFormat)
    return QtCore.QSettings("modalviewer", "modalviewer")


class ComputeError(RuntimeError):
    """A computation started from the scripting API failed; the message is for users."""


def _combo() -> QtWidgets.QComboBox:
    """A combo box as wide as 14 characters, not as its longest item (which made the
    Compute dock wider than its 340-pixel limit, so its right edge was cut off)."""
    combo = QtWidgets.QComboBox()
    combo.setSizeAdjustPolicy(
        QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
    )
    combo.setMinimumContentsLength(14)
    return combo


class MainWindow(QtWidgets.QMainWindow):
    """The modalviewer main window."""

    meshLoaded = QtCore.Signal(str)
    spectrumReady = QtCore.Signal(str)

    def __init__(self, force_offscreen: bool | None = None, cache: SpectrumCache | None = None):
        super().__init__()
        self.setWindowTitle("modalviewer")
        self.setAcceptDrops(True)
        self.settings = settings()
        self.cache = cache or SpectrumCache()
        self.viewport = make_viewport(self, force_offscreen)
        self.plotter = self.viewport.plotter
        self.setCentralWidget(self.viewport.widget)
        self.viewport.clicked.connect(self._on_view_clicked)

        self.mesh: Mesh | None = None
        self.mesh_path: Path | None = None
        self.compute_mesh: Mesh | None = None  # the (possibly rescaled) mesh spectra use
        self.scene: MeshScene | None = None
        self.normals: np.ndarray | None = None
        self.spectra: dict[str, Spectrum] = {}
        self.current_operator: str | None = None
        self.mode_index = 0
        self.picked: int | None = None
        self.display = "mode"  # mode | distance | signature | curvature
        self.distance_kind = "vibration"
        self.distance_display = "continuous"
        self.threshold_fraction = 0.2
        self.last_distance: np.ndarray | None = None
        self.last_error: str | None = None
        self._tables: dict[tuple, SignatureTable] = {}
        self._table_jobs: dict[int, Job] = {}
        self._job: Job | None = None
        self._pending_after_compute = None
        self._phase = 0.0
        self._last_tick = None
        self.frame_times: list[float] = []
        self.compare: CompareWindow | None = None

        self._build_docks()
        self._build_menus()
        self.statusBar().showMessage("Open a mesh to begin (File > Open, Ctrl+O).")
        self.progress = QtWidgets.QProgressBar()
        self.progress.setMaximumWidth(240)
        self.progress.setRange(0, 1000)
        self.progress.hide()
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.setToolTip("Cancel the running computation (Esc)")
        self.cancel_button.clicked.connect(self.cancel_computation)
        self.cancel_button.hide()
        self.statusBar().addPermanentWidget(self.progress)
        self.statusBar().addPermanentWidget(self.cancel_button)

        self.anim_timer = QtCore.QTimer(self)
        self.anim_timer.setInterval(16)
        self.anim_timer.timeout.connect(self._animate_step)
        self._restore_settings()
        self._update_enabled()

    # ================================================================== UI
    def _build_docks(self) -> None:
        # --- compute
        box = QtWidgets.QWidget()
        form = QtWidgets.QFormLayout(box)
        self.operator_combo = _combo()
        for key, label in OPERATOR_LABELS.items():
            self.operator_combo.addItem(label, key)
        self.operator_combo.currentIndexChanged.connect(self._on_operator_changed)
        self.k_spin = QtWidgets.QSpinBox()
        self.k_spin.setRange(1, 2000)
        self.k_spin.setValue(100)
        self.k_spin.setToolTip("Number of modes (lowest eigenpairs) to compute")
        self.bending_spin = QtWidgets.QDoubleSpinBox()
        self.membrane_spin = QtWidgets.QDoubleSpinBox()
        for spin in (self.bending_spin, self.membrane_spin):
            spin.setDecimals(4)
            spin.setRange(0.0, 1e6)
            spin.setValue(1.0)
        self.rescale_check = QtWidgets.QCheckBox("Rescale to unit area (default: off)")
        self.rescale_check.setToolTip(
            "Compute on a copy scaled to total area 1. The shells spectrum depends on the "
            "absolute size; rescaling makes meshes of different sizes comparable."
        )
        self.coarse_check = QtWidgets.QCheckBox("Coarse-to-fine (default: off)")
        self.coarse_check.setToolTip(
            "Compute on a copy decimated to about a fifth of the vertices and carry the modes "
            "to this mesh by nearest vertex (paper Section 7): much faster on big meshes."
        )
        self.compute_button = QtWidgets.QPushButton("Compute spectrum")
        self.compute_button.setToolTip("Compute the selected operator's spectrum (Ctrl+R)")
        self.compute_button.clicked.connect(lambda: self.compute(wait=False))
        form.addRow("Operator", self.operator_combo)
        form.addRow("Modes k", self.k_spin)
        form.addRow("Bending weight", self.bending_spin)
        form.addRow("Membrane weight", self.membrane_spin)
        form.addRow(self.rescale_check)
        form.addRow(self.coarse_check)
        form.addRow(self.compute_button)
        self.mesh_info = QtWidgets.QLabel("No mesh")
        self.mesh_info.setWordWrap(True)
        form.addRow(self.mesh_info)
        self._add_dock("Compute", box, QtCore.Qt.DockWidgetArea.LeftDockWidgetArea)

        # --- modes
        box = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(box)
        row = QtWidgets.QHBoxLayout()
        self.mode_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.mode_spin = QtWidgets.QSpinBox()
        self.mode_slider.valueChanged.connect(self.mode_spin.setValue)
        self.mode_spin.valueChanged.connect(self.mode_slider.setValue)
        self.mode_spin.valueChanged.connect(self.show_mode)
        row.addWidget(QtWidgets.QLabel("Mode"))
        row.addWidget(self.mode_slider, 1)
        row.addWidget(self.mode_spin)
        lay.addLayout(row)
        self.eigen_label = QtWidgets.QLabel("lambda = -")
        lay.addWidget(self.eigen_label)
        self.spectrum_plot = LinePlot("Spectrum", "mode index", "eigenvalue")
        self.spectrum_plot.sampleClicked.connect(self.mode_spin.setValue)
        lay.addWidget(self.spectrum_plot)
        form = QtWidgets.QFormLayout()
        self.color_combo = _combo()
        self.color_combo.addItem("Normal component", "normal")
        self.color_combo.addItem("Magnitude", "magnitude")
        self.color_combo.setToolTip("Scalar shown for 3D vibration modes")
        self.color_combo.currentIndexChanged.connect(lambda _: self._refresh())
        self.iso_spin = QtWidgets.QSpinBox()
        self.iso_spin.setRange(0, 60)
        self.iso_spin.setValue(12)
        self.iso_spin.valueChanged.connect(lambda _: self._refresh())
        form.addRow("Colour 3D modes by", self.color_combo)
        form.addRow("Isolines", self.iso_spin)
        self.play_button = QtWidgets.QPushButton("Play")
        self.play_button.setCheckable(True)
        self.play_button.setToolTip("Animate the mode (Space)")
        self.play_button.toggled.connect(self.set_animating)
        self.amp_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.amp_slider.setRange(0, 100)
        self.amp_slider.setValue(8)
        self.speed_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.speed_slider.setRange(1, 100)
        self.speed_slider.setValue(30)
        form.addRow(self.play_button)
        form.addRow("Amplitude", self.amp_slider)
        form.addRow("Speed", self.speed_slider)
        lay.addLayout(form)
        self._add_dock("Modes", box, QtCore.Qt.DockWidgetArea.RightDockWidgetArea)

        # --- distances
        box = QtWidgets.QWidget()
        form = QtWidgets.QFormLayout(box)
        self.kind_combo = _combo()
        for key, label in DISTANCE_LABELS.items():
            self.kind_combo.addItem(label, key)
        self.display_combo = _combo()
        self.display_combo.addItem("Continuous (white to red)", "continuous")
        self.display_combo.addItem("Threshold (blue = similar)", "threshold")
        self.threshold_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.threshold_slider.setRange(1, 1000)
        self.threshold_slider.setValue(200)
        self.threshold_slider.valueChanged.connect(self._on_threshold_slider)
        self.t1_edit = QtWidgets.QLineEdit()
        self.t2_edit = QtWidgets.QLineEdit()
        for edit in (self.t1_edit, self.t2_edit):
            edit.setPlaceholderText("default")
            edit.setValidator(QtGui.QDoubleValidator(0.0, 1e30, 12))
        self.pick_label = QtWidgets.QLabel("Click the surface to pick a vertex.")
        self.pick_label.setWordWrap(True)
        distance_button = QtWidgets.QPushButton("Show distance")
        distance_button.clicked.connect(lambda: self.show_distance())
        self.kind_combo.currentIndexChanged.connect(lambda _: self._distance_inputs_changed())
        self.display_combo.currentIndexChanged.connect(lambda _: self._distance_inputs_changed())
        form.addRow("Kind", self.kind_combo)
        form.addRow("Display", self.display_combo)
        form.addRow("Threshold", self.threshold_slider)
        form.addRow("t1", self.t1_edit)
        form.addRow("t2", self.t2_edit)
        form.addRow(self.pick_label)
        form.addRow(distance_button)
        self.scale_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.scale_slider.setRange(0, 99)
        self.scale_slider.setValue(50)
        self.scale_slider.valueChanged.connect(lambda v: self.show_signature(v))
        form.addRow("Signature at scale", self.scale_slider)
        self.signature_plot = LinePlot("Signature of the picked vertex", "t (log)", "S_t")
        form.addRow(self.signature_plot)
        self._add_dock(
            "Distances and signatures", box, QtCore.Qt.DockWidgetArea.RightDockWidgetArea
        )

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

    def _action(self, menu, text, slot, shortcut=None, tip=None) -> QtGui.QAction:
        action = QtGui.QAction(text, self)
        if shortcut:
            action.setShortcut(QtGui.QKeySequence(shortcut))
        if tip:
            action.setStatusTip(tip)
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_menus(self) -> None:
        bar = self.menuBar()
        m = bar.addMenu("&File")
        self._action(m, "&Open mesh...", self._open_dialog, "Ctrl+O")
        self.recent_menu = m.addMenu("Open &recent")
        m.addSeparator()
        self._action(m, "Export &screenshot...", self._screenshot_dialog, "Ctrl+E")
        self._action(m, "Export per-vertex &field (PLY/VTP)...", self._field_dialog, "Ctrl+Shift+E")
        self._action(m, "Export s&pectrum (.npz)...", self._spectrum_dialog, "Ctrl+Shift+S")
        m.addSeparator()
        self._action(m, "&Quit", self.close, "Ctrl+Q")
        m = bar.addMenu("&Compute")
        self._action(m, "&Compute spectrum", lambda: self.compute(wait=False), "Ctrl+R")
        self._action(m, "C&ancel", self.cancel_computation, "Esc")
        m = bar.addMenu("&View")
        self._action(m, "&Next mode", lambda: self.mode_spin.setValue(self.mode_index + 1), "Right")
        self._action(
            m, "&Previous mode", lambda: self.mode_spin.setValue(self.mode_index - 1), "Left"
        )
        self._action(m, "Play / pause animation", self.play_button.toggle, "Space")
        self._action(m, "Show &mode", lambda: self.show_mode(self.mode_index), "M")
        self._action(m, "Show &distance", lambda: self.show_distance(), "D")
        self._action(m, "Show &curvature sqrt(k1^2 + k2^2)", self.show_curvature, "C")
        self.colorbar_action = self._action(m, "Colour &bar", self._toggle_colorbar, "B")
        self.colorbar_action.setCheckable(True)
        self._action(m, "&Reset camera", self._reset_camera, "R")
        m.addSeparator()
        self._action(
            m,
            "Compare &operators (Laplacian, E_D^N, shells normal)",
            lambda: self.open_comparison(
                ["laplacian", "modified_dirichlet", "shells_normal"], wait=False
            ),
            "Ctrl+1",
        )
        self._action(
            m,
            "Compare d&istances (vibration, heat kernel)",
            lambda: self.open_comparison(["vibration", "hks"], wait=False),
            "Ctrl+2",
        )
        m = bar.addMenu("&Help")
        self._action(m, "&About", self._about)

    def _about(self) -> None:
        QtWidgets.QMessageBox.about(
            self,
            "About modalviewer",
            "modalviewer: modal shape analysis beyond the Laplacian.\n\n"
            "Laplacian, modified Dirichlet energy E_D^N and Discrete Shells vibration "
            "modes; heat kernel, feature and vibration signatures and distances.",
        )

    # ============================================================ messages
    def show_error(self, message: str, title: str = "modalviewer") -> None:
        """A non-blocking warning dialog with a human message; the app keeps running."""
        self.last_error = message
        log.warning("%s", message)
        self.statusBar().showMessage(message, 10000)
        if os.environ.get("MODALVIEWER_NO_DIALOGS"):
            return
        box = QtWidgets.QMessageBox(
            QtWidgets.QMessageBox.Icon.Warning,
            title,
            message,
            QtWidgets.QMessageBox.StandardButton.Ok,
            self,
        )
        box.setAttribute(QtCore.Qt.WidgetAttribute.WA_DeleteOnClose)
        box.open()

    def _update_enabled(self) -> None:
        has_mesh = self.mesh is not None
        running = self._job is not None
        self.compute_button.setEnabled(has_mesh and not running)
        has_spec = self.current_operator in self.spectra
        for w in (self.mode_slider, self.mode_spin, self.play_button):
            w.setEnabled(has_spec)
        shells = self.current_operator == "shells"
        self.color_combo.setEnabled(shells)
        self.progress.setVisible(running)
        self.cancel_button.setVisible(running)

    # =========================================================== settings
    def _restore_settings(self) -> None:
        s = self.settings
        geometry = s.value("window/geometry")
        if geometry is not None:
            self.restoreGeometry(geometry)
        else:
            self.resize(1280, 820)
        state = s.value("window/state")
        if state is not None:
            self.restoreState(state)
        self.iso_spin.setValue(int(s.value("view/isolines", 12)))
        self.amp_slider.setValue(int(s.value("view/amplitude", 8)))
        self.speed_slider.setValue(int(s.value("view/speed", 30)))
        idx = self.color_combo.findData(s.value("view/shell_color", "normal"))
        self.color_combo.setCurrentIndex(max(idx, 0))
        idx = self.operator_combo.findData(s.value("compute/operator", "modified_dirichlet"))
        self.operator_combo.setCurrentIndex(max(idx, 0))
        self.bending_spin.setValue(float(s.value("compute/bending", 1.0)))
        self.membrane_spin.setValue(float(s.value("compute/membrane", 1.0)))
        self.rescale_check.setChecked(str(s.value("compute/rescale", "false")).lower() == "true")
        self._rebuild_recent()

    def save_settings(self) -> None:
        s = self.settings
        s.setValue("window/geometry", self.saveGeometry())
        s.setValue("window/state", self.saveState())
        s.setValue("view/isolines", self.iso_spin.value())
        s.setValue("view/amplitude", self.amp_slider.value())
        s.setValue("view/speed", self.speed_slider.value())
        s.setValue("view/shell_color", self.color_combo.currentData())
        s.setValue("compute/operator", self.operator_combo.currentData())
        s.setValue("compute/bending", self.bending_spin.value())
        s.setValue("compute/membrane", self.membrane_spin.value())
        s.setValue("compute/rescale", "true" if self.rescale_check.isChecked() else "false")
        s.sync()

    def _recent_files(self) -> list[str]:
        value = self.settings.value("files/recent", [])
        if isinstance(value, str):
            value = [value]
        return [str(v) for v in (value or [])]

    def _rebuild_recent(self) -> None:
        self.recent_menu.clear()
        for path in self._recent_files():
            action = self.recent_menu.addAction(path)
            action.triggered.connect(lambda _=False, p=path: self.open_mesh(p))
        self.recent_menu.setEnabled(bool(self._recent_files()))

    def _remember_file(self, path: Path) -> None:
        recent = [str(path)] + [p for p in self._recent_files() if p != str(path)]
        self.settings.setValue("files/recent", recent[:10])
        self.settings.setValue("files/last_dir", str(path.parent))
        self._rebuild_recent()

    def closeEvent(self, event):  # noqa: N802
        self.set_animating(False)
        if self.compare is not None:
            self.compare.close()
        if self._job is not None:
            self._job.cancel()
            self._job.wait(5.0)
            self._job = None
        self.save_settings()
        self.viewport.close_plotter()
        super().closeEvent(event)

    # ============================================================= loading
    def _open_dialog(self) -> None:
        start = str(self.settings.value("files/last_dir", str(ASSETS)))
        patterns = " ".join(f"*{e}" for e in SUPPORTED_EXTENSIONS)
        path, _ = QtWidgets.QFileDialog.getOpenFileName(
            self, "Open mesh", start, f"Meshes ({patterns});;All files (*)"
        )
        if path:
            self.open_mesh(path)

    def dragEnterEvent(self, event):  # noqa: N802
        if event.mimeData().hasUrls():
            event.acceptProposedAction()

    def dropEvent(self, event):  # noqa: N802
        urls = event.mimeData().urls()
        if urls:
            self.open_mesh(urls[0].toLocalFile())

    def open_mesh(self, path) -> bool:
        """Load a mesh file and show it; returns False (after a dialog) if it failed."""
        path = Path(path)
        QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.WaitCursor)
        try:
            mesh = load_mesh(path)
        except MeshError as exc:
            self.show_error(str(exc), "Cannot open mesh")
            return False
        except OSError as exc:
            self.show_error(
                f"{path.name}: cannot be read ({exc.strerror or exc})", "Cannot open mesh"
            )
            return False
        finally:
            QtWidgets.QApplication.restoreOverrideCursor()
        self.set_mesh(mesh, path)
        self._remember_file(path.resolve())
        return True

    def set_mesh(self, mesh: Mesh, path: Path | None = None) -> None:
        """Show ``mesh``; drops spectra of the previous mesh and cancels its computation."""
        self.set_animating(False)
        if self._job is not None:
            self._job.cancel()
            self._job = None
            self._end_wait(error="superseded: another mesh was opened")
        self._pending_after_compute = None
        if self.scene is not None:
            self.scene.remove()
        if self.compare is not None:
            self.compare.close()
        self.mesh, self.mesh_path = mesh, path
        self.compute_mesh = None
        self.spectra.clear()
        self._tables.clear()
        self.picked = None
        self.last_distance = None
        self.normals = vertex_normals(mesh)
        self.scene = MeshScene(self.plotter, mesh, self.normals)
        self._reset_camera()
        self.display = "mode"
        self.k_spin.setValue(default_k(mesh.n_vertices))
        name = path.name if path else "mesh"
        self.setWindowTitle(f"modalviewer - {name}")
        self.mesh_info.setText(str(mesh.report))
        self.statusBar().showMessage(str(mesh.report), 15000)
        self.spectrum_plot.set_data([], [])
        self.signature_plot.set_data([], [])
        self.pick_label.setText("Click the surface to pick a vertex.")
        self._update_enabled()
        self.viewport.request_render()
        self.meshLoaded.emit(str(path) if path else "")

    # =========================================================== computing
    def _on_operator_changed(self, _index: int) -> None:
        op = self.operator_combo.currentData()
        shells = op in ("shells", "shells_normal")
        self.bending_spin.setEnabled(shells)
        self.membrane_spin.setEnabled(shells)
        if op in self.spectra:
            self.current_operator = op
            self._spectrum_changed()

    def _mesh_for_compute(self) -> Mesh:
        assert self.mesh is not None
        if not self.rescale_check.isChecked():
            return self.mesh
        factor = 1.0 / np.sqrt(self.mesh.total_area)
        return Mesh(self.mesh.vertices * factor, self.mesh.faces, report=self.mesh.report)

    def compute(
        self, operator: str | None = None, k: int | None = None, wait: bool = True, then=None
    ):
        """Compute a spectrum in the worker thread (cached on disk).

        With ``wait=True`` the call returns the Spectrum once ready (the event loop keeps
        running meanwhile) and raises ComputeError on failure.  ``then`` is called
        with the spectrum when it arrives.
        """
        if self.mesh is None:
            self.show_error("Open a mesh first.")
            return None
        if operator is not None:
            self.operator_combo.setCurrentIndex(self.operator_combo.findData(operator))
        operator = self.operator_combo.currentData()
        k = int(k if k is not None else self.k_spin.value())
        self.k_spin.setValue(k)
        bending, membrane = self.bending_spin.value(), self.membrane_spin.value()
        # Whether shells can run on this mesh (manifold, oriented) is checked by the core
        # in the worker, which fails with a clear message: the check sorts all half-edges
        # (0.16 s at 130k vertices), too long for the GUI thread.
        if self._job is not None:
            self._job.cancel()
            self._job = None
        mesh = self._mesh_for_compute()
        self.compute_mesh = mesh
        coarse = self.coarse_check.isChecked()
        n_solved = round(COARSE_FRACTION * mesh.n_vertices) if coarse else mesh.n_vertices
        refusal = self._too_big(n_solved, operator, k)
        if refusal:
            self.show_error(refusal, "Computation too large")
            if wait:
                raise ComputeError(refusal)
            return None
        if coarse:
            return self._compute_coarse(mesh, operator, k, bending, membrane, wait, then)
        cache = self.cache
        cached = cache.get(mesh, operator, k, bending, membrane)
        if cached is not None:
            self._prepare_table(cached)
            self._accept_spectrum(cached, from_cache=True)
            if then:
                then(cached)
            return cached

        if mesh.n_vertices * (3 if operator == "shells" else 1) >= PROCESS_THRESHOLD:
            target = cache.writable_path(mesh, operator, k, bending, membrane)

            def work(progress, cancel):
                return compute_in_process(
                    mesh, operator, k, bending, membrane, target, progress, cancel
                )
        else:

            def work(progress, cancel):
                spec = compute_spectrum(mesh, operator, k, bending, membrane, progress, cancel)
                cache.put(mesh, spec, k, bending, membrane)
                return spec

        message = f"Computing {OPERATOR_LABELS[operator]} ({k} modes)..."
        return self._start_job(work, operator, wait, then, message)

    def _start_job(self, work, operator, wait, then, message=None):
        t_range = self._t_range()

        def work_and_table(progress, cancel):
            # The signature table for distances is built here too, off the GUI thread:
            # at 130k vertices it takes 0.4 s, which the first pick would otherwise stall.
            spec = work(progress, cancel)
            progress("preparing distances", 0.99)
            if cancel():
                raise Cancelled()
            return spec, SignatureTable(spec, t_range=t_range), t_range

        job = Job(work_and_table, tag=(self.mesh.hash, operator))
        job.progress.connect(self._on_job_progress)
        job.finished.connect(self._on_job_finished)
        job.failed.connect(self._on_job_failed)
        job.cancelled.connect(self._on_job_cancelled)
        self._job = job
        self._pending_after_compute = then
        self._job_started = time.perf_counter()
        self.progress.setValue(0)
        self.statusBar().showMessage(message or f"Computing {OPERATOR_LABELS[operator]}...")
        job.start()
        self._update_enabled()
        if not wait:
            return None
        self._wait_result = {}
        self._wait_loop = QtCore.QEventLoop()
        self._wait_loop.exec()
        self._wait_loop = None
        result = self._wait_result
        if "error" in result:
            raise ComputeError(result["error"])
        return result.get("value")

    def _end_wait(self, **result) -> None:
        if getattr(self, "_wait_loop", None) is not None:
            self._wait_result = result
            self._wait_loop.quit()

    def _too_big(self, n_solved: int, operator: str, k: int) -> str | None:
        """A message if the estimated memory exceeds 3/4 of this machine's memory.

        n_solved: vertices of the mesh the eigenproblem is solved on (the coarse copy's
        with Coarse-to-fine).
        """
        n = n_solved * (3 if operator == "shells" else 1)
        nnz = n_solved * (7 if operator != "shells" else 7 * 9 * 2)
        seconds, needed = estimate_cost(n, min(k, n), nnz)
        available = _physical_memory()
        if available and needed > 0.75 * available:
            return (
                f"{OPERATOR_LABELS[operator]} with {k} modes on {n_solved} vertices "
                f"needs about {needed / 2**30:.1f} GiB of memory and {seconds / 60:.0f} min; "
                f"this machine has {available / 2**30:.1f} GiB. Compute fewer modes, or tick "
                "Coarse-to-fine to compute on a decimated copy."
            )
        if seconds > 300:
            self.statusBar().showMessage(
                f"This will take about {seconds / 60:.0f} min (Esc cancels; Coarse-to-fine is "
                "much faster).",
                20000,
            )
        return None

    def _compute_coarse(self, mesh, operator, k, bending, membrane, wait, then):
        """Decimate ``mesh``, compute on the copy and carry the spectrum back, all in the
        worker (VTK's decimation takes about a second at 130k vertices)."""

        def work(progress, cancel):
            progress("decimating", 0.0)
            coarse = decimated_copy(mesh, COARSE_FRACTION)
            k_coarse = min(k, coarse.n_vertices * (3 if operator == "shells" else 1))
            spec = compute_spectrum(coarse, operator, k_coarse, bending, membrane, progress, cancel)
            return transfer_spectrum(spec, coarse, mesh)

        message = (
            f"Computing on a coarse copy (about {COARSE_FRACTION:.0%} of "
            f"{mesh.n_vertices} vertices)..."
        )
        return self._start_job(work, operator, wait, then, message)

    def cancel_computation(self) -> None:
        if self._job is not None:
            self._job.cancel()
            self.statusBar().showMessage("Cancelling...")

    def _is_current(self, job_id: int) -> bool:
        return self._job is not None and self._job.id == job_id

    def _on_job_progress(self, job_id: int, stage: str, fraction: float) -> None:
        if self._is_current(job_id):
            self.progress.setValue(int(1000 * fraction))
            self.progress.setFormat(f"{stage} %p%")

    def _on_job_finished(self, job_id: int, result) -> None:
        if not self._is_current(job_id):
            return  # a result for a mesh that is no longer shown, or a superseded job
        spec, table, t_range = result
        if self.compute_mesh is None or spec.mesh_hash != self.compute_mesh.hash:
            return
        self._job = None
        self._keep_table((spec.operator, id(spec), t_range), table)
        elapsed = time.perf_counter() - self._job_started
        try:
            self._accept_spectrum(spec, elapsed=elapsed)
            then, self._pending_after_compute = self._pending_after_compute, None
            if then:
                then(spec)
        finally:
            self._end_wait(value=spec)

    def _on_job_failed(self, job_id: int, message: str, details: str) -> None:
        if not self._is_current(job_id):
            return
        self._job = None
        log.error("computation failed: %s\n%s", message, details)
        self._update_enabled()
        self.show_error(f"The computation failed: {message}", "Computation failed")
        self._end_wait(error=message)

    def _on_job_cancelled(self, job_id: int) -> None:
        if not self._is_current(job_id):
            return
        self._job = None
        self._update_enabled()
        self.statusBar().showMessage("Computation cancelled.", 5000)
        self._end_wait(error="cancelled")

    def _accept_spectrum(self, spec: Spectrum, from_cache=False, elapsed=None) -> None:
        self.spectra[spec.operator] = spec
        self.current_operator = spec.operator
        self._update_enabled()
        worst = float(np.max(spec.residuals[~spec.zero_mode_mask()], initial=0.0))
        how = "from cache" if from_cache else f"in {elapsed:.1f} s"
        self.statusBar().showMessage(
            f"{OPERATOR_LABELS[spec.operator]}: {spec.k} modes {how}; "
            f"largest relative residual {worst:.1e}.",
            15000,
        )
        self._spectrum_changed()
        self.spectrumReady.emit(spec.operator)

    def _spectrum_changed(self) -> None:
        spec = self.spectra[self.current_operator]
        self.mode_spin.blockSignals(True)
        self.mode_slider.setRange(0, spec.k - 1)
        self.mode_spin.setRange(0, spec.k - 1)
        first = int(np.argmax(~spec.zero_mode_mask())) if (~spec.zero_mode_mask()).any() else 0
        self.mode_spin.setValue(first)
        self.mode_slider.setValue(first)
        self.mode_spin.blockSignals(False)
        self.spectrum_plot.set_data(
            np.arange(spec.k),
            spec.eigenvalues,
            first,
            title=f"Spectrum: {OPERATOR_LABELS[spec.operator]}",
        )
        self.show_mode(first)

    # ================================================================ modes
    def mode_fields(self, spec: Spectrum, j: int):
        """(scalar to colour, displacement (n, 3)) of mode j."""
        phi = spec.mode(j)
        if spec.is_vector:
            scalar = (
                np.einsum("ij,ij->i", phi, self.normals)
                if self.color_combo.currentData() == "normal"
                else np.linalg.norm(phi, axis=1)
            )
            disp = phi
        else:
            scalar = phi
            disp = phi[:, None] * self.normals
        peak = float(np.max(np.linalg.norm(disp, axis=1))) or 1.0
        return scalar, disp / peak

    def show_mode(self, index: int) -> None:
        """Colour the surface by mode ``index`` of the current spectrum."""
        if self.current_operator not in self.spectra or self.scene is None:
            return
        spec = self.spectra[self.current_operator]
        index = int(np.clip(index, 0, spec.k - 1))
        self.mode_index = index
        if self.mode_spin.value() != index:
            self.mode_spin.blockSignals(True)
            self.mode_spin.setValue(index)
            self.mode_slider.setValue(index)
            self.mode_spin.blockSignals(False)
        lam = float(spec.eigenvalues[index])
        freq = np.sqrt(max(lam, 0.0))
        zero = " (zero mode)" if spec.zero_mode_mask()[index] else ""
        self.eigen_label.setText(f"lambda_{index} = {lam:.6g}   sqrt(lambda) = {freq:.6g}{zero}")
        self.spectrum_plot.set_highlight(index)
        scalar, disp = self.mode_fields(spec, index)
        diverging = not (spec.is_vector and self.color_combo.currentData() == "magnitude")
        self.scene.set_displacement_scale(0.0)
        self.scene.show_field(
            scalar,
            "diverging" if diverging else "sequential",
            isolines=self.iso_spin.value(),
            displacement=disp,
            name=f"{spec.operator} mode {index}",
        )
        self.display = "mode"
        self._update_colorbar()
        self.viewport.request_render()
        if self.compare is not None and not self.compare.distances:
            self.compare.show_mode(index)

    def _refresh(self) -> None:
        if self.display == "mode":
            self.show_mode(self.mode_index)
        elif self.display == "distance":
            self._draw_distance()

    # ============================================================ animation
    def set_animating(self, on: bool) -> None:
        """Start or stop the animation of the shown mode (only modes are animated)."""
        on = bool(on) and self.display == "mode" and self.scene is not None
        if self.play_button.isChecked() != on:
            self.play_button.blockSignals(True)
            self.play_button.setChecked(on)
            self.play_button.blockSignals(False)
        self.play_button.setText("Pause" if on else "Play")
        if on and self.display == "mode" and self.scene is not None:
            self._last_tick = time.perf_counter()
            self.anim_timer.start()
        else:
            self.anim_timer.stop()
            if self.scene is not None:
                self.scene.set_displacement_scale(0.0)
                self.viewport.request_render()

    def animation_frame(self, phase: float) -> float:
        """Move the surface to the given phase (radians); returns the app's time in s."""
        started = time.perf_counter()
        amplitude = self.amp_slider.value() / 100.0 * 0.25 * self.mesh.bounding_box_diagonal
        self.scene.set_displacement_scale(amplitude * np.sin(phase))
        self.viewport.request_render()
        return time.perf_counter() - started

    def _animate_step(self) -> None:
        if self.scene is None or self.display != "mode":
            self.set_animating(False)
            return
        now = time.perf_counter()
        dt = now - (self._last_tick or now)
        self._last_tick = now
        self._phase += dt * self.speed_slider.value() / 10.0
        self.frame_times.append(self.animation_frame(self._phase))
        del self.frame_times[:-200]

    # ============================================================ distances
    def _on_view_clicked(self, x: float, y: float) -> None:
        if self.scene is None:
            return
        vertex = self.scene.vertex_at_display(x, y)
        if vertex is not None:
            self.pick_vertex(vertex)

    def pick_vertex(self, index: int) -> None:
        """Pick vertex ``index`` (as a click on it does): marker, distance map."""
        if self.scene is None:
            return
        index = int(index)
        if not 0 <= index < self.mesh.n_vertices:
            self.show_error(f"Vertex {index} does not exist (0..{self.mesh.n_vertices - 1}).")
            return
        self.picked = index
        self.set_animating(False)
        self.scene.show_marker(index)
        self.pick_label.setText(
            f"Picked vertex {index} at {np.round(self.mesh.vertices[index], 4)}"
        )
        self.show_distance()

    def _distance_inputs_changed(self) -> None:
        if self.display == "distance":
            self.show_distance()

    def _t_range(self):
        try:
            t1, t2 = float(self.t1_edit.text()), float(self.t2_edit.text())
        except ValueError:
            return None
        return (t1, t2) if 0 < t1 < t2 else None

    def _table(self, operator: str) -> SignatureTable:
        spec = self.spectra[operator]
        key = (operator, id(spec), self._t_range())
        table = self._tables.get(key)
        if table is None:
            table = SignatureTable(spec, t_range=self._t_range())
            self._keep_table(key, table)
        return table

    def _prepare_table(self, spec: Spectrum) -> None:
        """Build the signature table of ``spec`` in a background thread (0.4 s at 130k
        vertices) so that the first pick finds it ready; a pick before then builds it."""
        key = (spec.operator, id(spec), self._t_range())
        job = Job(lambda _progress, _cancel: (key, SignatureTable(spec, t_range=key[2])))
        job.finished.connect(self._on_table_ready)
        job.failed.connect(self._on_table_failed)
        self._table_jobs[job.id] = job  # referenced until it reports
        job.start()

    def _on_table_ready(self, job_id: int, result) -> None:
        self._table_jobs.pop(job_id, None)
        key, table = result
        current = self.spectra.get(key[0])
        if current is not None and id(current) == key[1] and key not in self._tables:
            self._keep_table(key, table)

    def _on_table_failed(self, job_id: int, message: str, details: str) -> None:
        self._table_jobs.pop(job_id, None)  # a pick builds the table itself
        log.warning("signature table not prepared: %s\n%s", message, details)

    def _keep_table(self, key, table: SignatureTable) -> None:
        self._tables[key] = table
        if key[2] is None:
            self.t1_edit.setPlaceholderText(f"default {table.times[0]:.4g}")
            self.t2_edit.setPlaceholderText(f"default {table.times[-1]:.4g}")

    def show_distance(
        self, kind: str | None = None, display: str | None = None, threshold: float | None = None
    ) -> np.ndarray | None:
        """Distance map from the picked vertex.

        kind: "vibration" | "feature" | "hks"; display: "continuous" | "threshold";
        threshold: as a fraction of the largest distance (0..1).  The needed spectrum is
        computed in the worker if missing; the map appears when it is ready.
        """
        if kind is not None:
            self.kind_combo.setCurrentIndex(self.kind_combo.findData(kind))
        if display is not None:
            self.display_combo.setCurrentIndex(self.display_combo.findData(display))
        if threshold is not None:
            self.threshold_fraction = float(np.clip(threshold, 0.001, 1.0))
            self.threshold_slider.blockSignals(True)
            self.threshold_slider.setValue(int(round(self.threshold_fraction * 1000)))
            self.threshold_slider.blockSignals(False)
        self.distance_kind = self.kind_combo.currentData()
        self.distance_display = self.display_combo.currentData()
        if self.scene is None:
            return None
        if self.picked is None:
            self.statusBar().showMessage("Click the surface to pick a vertex first.", 5000)
            return None
        operator = DISTANCE_OPERATOR[self.distance_kind]
        if operator not in self.spectra:
            self.statusBar().showMessage(
                f"Computing the spectrum for the {DISTANCE_LABELS[self.distance_kind].lower()}..."
            )
            self.compute(operator, wait=False, then=lambda _s: self.show_distance())
            return None
        self.last_distance = self._table(operator).distance_from(self.picked)
        self.display = "distance"
        self._draw_distance()
        self._plot_signature_curve(operator)
        if self.compare is not None and self.compare.distances:
            self.compare.show_distance()
        return self.last_distance

    def distance_map(self, kind: str) -> np.ndarray | None:
        """Distance of ``kind`` from the picked vertex, or None if its spectrum is missing."""
        operator = DISTANCE_OPERATOR[kind]
        if self.picked is None or operator not in self.spectra:
            return None
        return self._table(operator).distance_from(self.picked)

    def open_comparison(self, items: list[str], wait: bool = True) -> CompareWindow | None:
        """Linked side-by-side views of two or three operators or distance kinds.

        Missing spectra are computed first (in the worker; with ``wait`` this call
        returns once all are ready).
        """
        if self.mesh is None:
            self.show_error("Open a mesh first.")
            return None
        needed = [DISTANCE_OPERATOR.get(item, item) for item in items]
        missing = [op for op in dict.fromkeys(needed) if op not in self.spectra]
        if missing:
            if not wait:
                first, rest = missing[0], items
                self.compute(first, wait=False, then=lambda _s: self.open_comparison(rest, False))
                return None
            for op in missing:
                self.compute(op, wait=True)
        if self.compare is not None:
            self.compare.close()
        self.compare = CompareWindow(self, items)
        self.compare.show()
        self.compare.refresh()
        return self.compare

    def _draw_distance(self) -> None:
        d = self.last_distance
        if d is None or self.scene is None:
            return
        self.scene.set_displacement_scale(0.0)
        label = DISTANCE_LABELS[self.distance_kind]
        if self.distance_display == "threshold":
            thr = self.threshold_fraction * float(d.max())
            self.scene.show_field(
                (d > thr).astype(np.float64), "threshold", name=f"{label} < {thr:.4g}"
            )
            share = float(np.mean(d <= thr))
            self.statusBar().showMessage(
                f"{label}: threshold {thr:.4g}, {100 * share:.1f} % of vertices similar", 5000
            )
        else:
            self.scene.show_field(d, "sequential", isolines=0, name=label)
        self._update_colorbar()
        self.viewport.request_render()

    def set_threshold(self, fraction: float) -> float:
        """Move the threshold (fraction of the largest distance); returns the app's time in s."""
        started = time.perf_counter()
        self.threshold_fraction = float(np.clip(fraction, 0.001, 1.0))
        if self.display == "distance" and self.distance_display == "threshold":
            d = self.last_distance
            thr = self.threshold_fraction * float(d.max())
            self.scene.surface.point_data["field"] = (d > thr).astype(np.float64)
            self.viewport.request_render()
        return time.perf_counter() - started

    def _on_threshold_slider(self, value: int) -> None:
        self.set_threshold(value / 1000.0)

    def _plot_signature_curve(self, operator: str) -> None:
        table = self._table(operator)
        spec = self.spectra[operator]
        times, values = signature(spec, table.times, vertices=[self.picked])
        self.signature_plot.set_data(
            times,
            values[0],
            logx=True,
            markers=False,
            title=f"Signature of vertex {self.picked} ({spec.operator})",
        )

    def show_signature(self, sample: int) -> None:
        """Colour by the signature at scale sample ``sample`` of the distance kind's spectrum."""
        operator = DISTANCE_OPERATOR[self.kind_combo.currentData()]
        if operator not in self.spectra or self.scene is None:
            return
        table = self._table(operator)
        t = table.times[int(np.clip(sample, 0, len(table.times) - 1))]
        _, values = signature(self.spectra[operator], [t])
        self.scene.set_displacement_scale(0.0)
        self.scene.show_field(
            values[:, 0],
            "sequential",
            isolines=self.iso_spin.value(),
            name=f"signature t = {t:.4g}",
        )
        self.display = "signature"
        self._update_colorbar()
        self.statusBar().showMessage(f"Signature ({operator}) at t = {t:.4g}", 5000)
        self.viewport.request_render()

    def show_curvature(self) -> None:
        if self.scene is None:
            return
        self.scene.set_displacement_scale(0.0)
        curvature = total_curvature(self.mesh)
        hi = float(np.percentile(curvature, 98)) or 1.0
        self.scene.show_field(
            curvature, "sequential", clim=(0.0, hi), name="curvature sqrt(k1^2 + k2^2)"
        )
        self.display = "curvature"
        self._update_colorbar()
        self.viewport.request_render()

    # ================================================================ view
    def _reset_camera(self) -> None:
        """Front view (looking down -z, y up), turned a little, fitted to the mesh."""
        self.plotter.view_xy()
        self.plotter.camera.Azimuth(25)
        self.plotter.camera.Elevation(15)
        self.plotter.camera.OrthogonalizeViewUp()
        self.plotter.reset_camera()
        self.viewport.request_render()

    def _toggle_colorbar(self) -> None:
        self._update_colorbar()
        self.viewport.request_render()

    def _update_colorbar(self) -> None:
        if self.scene is None:
            return
        for title in list(self.plotter.scalar_bars.keys()):
            self.plotter.remove_scalar_bar(title)
        if (
            self.colorbar_action.isChecked()
            and self.display != "distance"
            or (self.colorbar_action.isChecked() and self.distance_display == "continuous")
        ):
            self.plotter.add_scalar_bar(
                self.scene.field_name or "value",
                mapper=self.scene._mapper,
                color="black",
                n_labels=3,
                fmt="%.3g",
            )

    # ============================================================== export
    def export_screenshot(
        self, path, scale: int = 1, transparent: bool = False, colorbar: bool | None = None
    ) -> Path:
        """Save the view as PNG (atomically); returns the path."""
        if colorbar is not None and colorbar != self.colorbar_action.isChecked():
            self.colorbar_action.setChecked(colorbar)
            self._update_colorbar()
        return save_screenshot(self.viewport, Path(path), scale=scale, transparent=transparent)

    def _screenshot_dialog(self) -> None:
        start = str(self.settings.value("files/screenshot_dir", str(SCREENSHOTS)))
        dialog = ScreenshotDialog(self, start)
        if dialog.exec() != QtWidgets.QDialog.DialogCode.Accepted:
            return
        path, scale, transparent, colorbar = dialog.values()
        try:
            out = self.export_screenshot(path, scale, transparent, colorbar)
        except (OSError, ValueError) as exc:
            self.show_error(f"Could not save the screenshot: {exc}")
            return
        self.settings.setValue("files/screenshot_dir", str(Path(path).parent))
        self.statusBar().showMessage(f"Saved {out}", 8000)

    def current_field(self) -> tuple[str, np.ndarray] | None:
        if self.scene is None:
            return None
        return (self.scene.field_name or "field"), np.array(self.scene.surface.point_data["field"])

    def export_field(self, path) -> Path:
        field = self.current_field()
        if field is None:
            raise ValueError("nothing to export: open a mesh first")
        name, values = field
        return save_field_mesh(Path(path), self.mesh, {name.replace(" ", "_"): values})

    def _field_dialog(self) -> None:
        if self.scene is None:
            return
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self,
            "Export per-vertex field",
            str(SCREENSHOTS / "field.vtp"),
            "VTK PolyData (*.vtp);;PLY (*.ply)",
        )
        if path:
            try:
                self.export_field(path)
            except (OSError, ValueError) as exc:
                self.show_error(f"Could not export the field: {exc}")

    def _spectrum_dialog(self) -> None:
        spec = self.spectra.get(self.current_operator)
        if spec is None:
            self.show_error("Compute a spectrum first.")
            return
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Export spectrum", f"{spec.operator}.npz", "NumPy (*.npz)"
        )
        if path:
            try:
                save_spectrum(spec, path)
            except OSError as exc:
                self.show_error(f"Could not save the spectrum: {exc}")


class ScreenshotDialog(QtWidgets.QDialog):
    def __init__(self, parent, start_dir: str):
        super().__init__(parent)
        self.setWindowTitle("Export screenshot")
        form = QtWidgets.QFormLayout(self)
        self.path_edit = QtWidgets.QLineEdit(str(Path(start_dir) / "figure.png"))
        browse = QtWidgets.QPushButton("...")
        browse.clicked.connect(self._browse)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.path_edit)
        row.addWidget(browse)
        form.addRow("File", row)
        self.scale = QtWidgets.QSpinBox()
        self.scale.setRange(1, 8)
        self.transparent = QtWidgets.QCheckBox("Transparent background")
        self.colorbar = QtWidgets.QCheckBox("Colour bar")
        form.addRow("Size multiplier", self.scale)
        form.addRow(self.transparent)
        form.addRow(self.colorbar)
        buttons = QtWidgets.QDialogButtonBox(
            QtWidgets.QDialogButtonBox.StandardButton.Save
            | QtWidgets.QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _browse(self) -> None:
        path, _ = QtWidgets.QFileDialog.getSaveFileName(
            self, "Screenshot", self.path_edit.text(), "PNG (*.png)"
        )
        if path:
            self.path_edit.setText(path)

    def values(self):
        return (
            self.path_edit.text(),
            self.scale.value(),
            self.transparent.isChecked(),
            self.colorbar.isChecked(),
        )
