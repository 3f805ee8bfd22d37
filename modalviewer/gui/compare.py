"""Side-by-side views with one shared camera: operators (Fig. 1) or distance kinds (Figs. 6, 7).

Each view draws its own :class:`MeshScene` of the main window's mesh; all renderers use
the same VTK camera, so rotating one rotates all.  The views follow the main window's
state (pick, threshold, isolines) and never change it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from qtpy import QtWidgets

from ..core.files import atomic_write
from ..core.operators import DISTANCE_KINDS, OPERATOR_INFO, operator_for_distance
from ..scene.mesh_scene import MeshScene
from .viewport import make_viewport
from .window_keys import dispatch_key, install_keys


class CompareWindow(QtWidgets.QWidget):
    """Two or three linked views; ``items`` are operators or distance kinds.

    It reads the main window's state (spectra, pick, threshold, isolines) and never
    changes it.  Operator views keep their own mode index, starting at the first
    non-zero mode; Left / Right step it, Esc and Ctrl+W close the window.
    """

    def __init__(self, main, items: list[str], force_offscreen: bool | None = None):
        super().__init__()
        if not 2 <= len(items) <= 3:
            raise ValueError("compare two or three operators or distance kinds")
        self.main = main
        self.state = main.state
        self.items = list(items)
        self.distances = all(item in DISTANCE_KINDS for item in items)
        self.setWindowTitle("modalviewer - compare " + " / ".join(_label(i) for i in items))
        layout = QtWidgets.QHBoxLayout(self)
        self.viewports, self.scenes, self.titles = [], [], []
        camera = None
        for item in self.items:
            column = QtWidgets.QVBoxLayout()
            title = QtWidgets.QLabel(_label(item))
            column.addWidget(title)
            viewport = make_viewport(self, force_offscreen)
            column.addWidget(viewport.widget, 1)
            layout.addLayout(column, 1)
            scene = MeshScene(viewport.plotter, self.state.mesh, self.state.derived.normals)
            if camera is None:
                camera = viewport.plotter.renderer.GetActiveCamera()
                camera.DeepCopy(main.plotter.renderer.GetActiveCamera())
            else:
                viewport.plotter.renderer.SetActiveCamera(camera)
            if hasattr(viewport, "cameraChanged"):
                viewport.cameraChanged.connect(self.render_all)
            self.viewports.append(viewport)
            self.scenes.append(scene)
            self.titles.append(title)
        first = self.items[0]
        self.mode_index = 0 if self.distances else self.state.first_nonzero_mode(first)
        for event in (self.state.events.pick, self.state.events.display, self.state.events.style):
            event.connect(self._on_state)
        # a spectrum replaced (the exact one after its preview) redraws the views
        self.state.events.spectra.connect(self._on_spectra)
        self._keys = install_keys(
            self,
            [
                ("Escape", self.close),
                ("Ctrl+W", self.close),
                ("Right", lambda: self._step(+1)),
                ("Left", lambda: self._step(-1)),
            ],
        )
        self.resize(420 * len(items), 480)

    def _step(self, step: int) -> None:
        if not self.distances:
            self.show_mode(self.mode_index + step)

    def keyPressEvent(self, event):  # noqa: N802
        """Esc and Ctrl+W close; Left / Right step the mode of operator views."""
        if not dispatch_key(self._keys, event):
            super().keyPressEvent(event)

    def _on_spectra(self, _operator: str | None = None) -> None:
        self._on_state()

    def _on_state(self) -> None:
        if self.distances:
            self.show_distance()
        else:
            self.show_mode(self.mode_index)

    def render_all(self) -> None:
        for viewport in self.viewports:
            viewport.request_render()

    def show_mode(self, index: int) -> None:
        """Mode ``index`` of each operator (those without a spectrum stay grey)."""
        self.mode_index = max(0, int(index))
        for item, scene, title in zip(self.items, self.scenes, self.titles, strict=True):
            spec = self.state.spectrum(item)
            if spec is None:
                title.setText(f"{_label(item)}: no spectrum")
                continue
            j = int(np.clip(self.mode_index, 0, spec.k - 1))
            scalar, disp = self.state.derived.mode_fields(spec, j)
            scene.show_field(
                scalar,
                "diverging",
                isolines=self.state.style.isolines,
                displacement=disp,
                name=f"{_label(item)} mode {j}",
            )
            lam = "0 (zero mode)" if spec.zero_mode_mask()[j] else f"{spec.eigenvalues[j]:.5g}"
            mark = " (preview)" if spec.is_preview else ""
            title.setText(f"{_label(item)}: mode {j}, lambda = {lam}{mark}")
        self.render_all()

    def show_distance(self) -> None:
        """Each kind's distance from the main window's picked vertex."""
        vertex = self.state.picked
        shown = self.state.picked_file_vertex  # the titles give the file's number
        display = self.state.display
        # every kind marks the share of the surface the main window's map marks (without
        # one, the share its threshold maps keep: DEFAULT_THRESHOLD_SHARE at first)
        share = self.state.derived.marked_share()
        if share is None and display.keep_share:
            share = display.threshold_share
        for item, scene, title in zip(self.items, self.scenes, self.titles, strict=True):
            scene.show_marker(vertex)
            d = self.state.derived.distance_map(item) if vertex is not None else None
            if d is None:
                need = (
                    "pick a vertex in the main window"
                    if vertex is None
                    else "its spectrum is not computed yet"
                )
                title.setText(f"{_label(item)}: {need}")
                continue
            spec = self.state.spectrum(operator_for_distance(item))
            mark = " (preview)" if spec is not None and spec.is_preview else ""
            if display.distance_display == "threshold":
                if share is None:
                    thr = display.threshold * float(d.max())
                else:
                    thr = self.state.derived.threshold_for_share(share, d) * float(d.max())
                scene.show_threshold(d, thr, name=_label(item))
                marked = 100.0 * self.state.derived.surface_share(d, thr)
                title.setText(
                    f"{_label(item)} from vertex {shown}: blue < {thr:.3g} ({marked:.1f} %)" + mark
                )
            else:
                scene.show_field(d, "sequential", name=_label(item))
                title.setText(f"{_label(item)} from vertex {shown}{mark}")
        self.render_all()

    def refresh(self) -> None:
        self._on_state()

    def grab_images(self) -> list[np.ndarray]:
        return [viewport.render_now() for viewport in self.viewports]

    def export_screenshot(self, path) -> Path:
        """The views side by side in one PNG (written atomically)."""
        from PIL import Image

        images = self.grab_images()
        height = max(img.shape[0] for img in images)
        canvas = np.full((height, sum(img.shape[1] for img in images), 3), 255, np.uint8)
        x = 0
        for img in images:
            canvas[: img.shape[0], x : x + img.shape[1]] = img[:, :, :3]
            x += img.shape[1]
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        return atomic_write(path, lambda tmp: Image.fromarray(canvas).save(tmp, format="PNG"))

    def closeEvent(self, event):  # noqa: N802
        for event_ in (self.state.events.pick, self.state.events.display, self.state.events.style):
            event_.disconnect(self._on_state)
        self.state.events.spectra.disconnect(self._on_spectra)
        for viewport in self.viewports:
            viewport.close_plotter()
        if self.main.compare is self:
            self.main.compare = None
        super().closeEvent(event)


def _label(item: str) -> str:
    if item in DISTANCE_KINDS:
        return DISTANCE_KINDS[item]
    return OPERATOR_INFO[item].short_label
