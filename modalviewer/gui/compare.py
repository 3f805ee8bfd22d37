"""Side-by-side views with one shared camera: operators (Fig. 1) or distance kinds (Figs. 6, 7).

Each view draws its own :class:`MeshScene` of the main window's mesh; all renderers use
the same VTK camera, so rotating one rotates all.  The main window drives the mode index
and the picked vertex.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
from qtpy import QtWidgets

from .scene import MeshScene
from .viewport import make_viewport

LABELS = {
    "laplacian": "Laplacian",
    "modified_dirichlet": "E_D^N",
    "shells": "Shells 3D",
    "shells_normal": "Shells normal",
    "vibration": "Vibration distance",
    "feature": "Feature distance",
    "hks": "Heat kernel distance",
}


class CompareWindow(QtWidgets.QWidget):
    """Two or three linked views; ``items`` are operators or distance kinds."""

    def __init__(self, main, items: list[str], force_offscreen: bool | None = None):
        super().__init__()
        if not 2 <= len(items) <= 3:
            raise ValueError("compare two or three operators or distance kinds")
        self.main = main
        self.items = list(items)
        self.distances = all(item in ("vibration", "feature", "hks") for item in items)
        self.setWindowTitle("modalviewer - compare " + " / ".join(LABELS[i] for i in items))
        layout = QtWidgets.QHBoxLayout(self)
        self.viewports, self.scenes, self.titles = [], [], []
        camera = None
        for item in self.items:
            column = QtWidgets.QVBoxLayout()
            title = QtWidgets.QLabel(LABELS[item])
            column.addWidget(title)
            viewport = make_viewport(self, force_offscreen)
            column.addWidget(viewport.widget, 1)
            layout.addLayout(column, 1)
            scene = MeshScene(viewport.plotter, main.mesh, main.normals)
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
        self.resize(420 * len(items), 480)

    def render_all(self) -> None:
        for viewport in self.viewports:
            viewport.request_render()

    def show_mode(self, index: int) -> None:
        """Mode ``index`` of each operator (those without a spectrum stay grey)."""
        for item, scene, title in zip(self.items, self.scenes, self.titles, strict=True):
            spec = self.main.spectra.get(item)
            if spec is None:
                title.setText(f"{LABELS[item]}: no spectrum")
                continue
            j = int(np.clip(index, 0, spec.k - 1))
            scalar, disp = self.main.mode_fields(spec, j)
            scene.show_field(
                scalar,
                "diverging",
                isolines=self.main.iso_spin.value(),
                displacement=disp,
                name=f"{item} mode {j}",
            )
            title.setText(f"{LABELS[item]}: mode {j}, lambda = {spec.eigenvalues[j]:.5g}")
        self.render_all()

    def show_distance(self) -> None:
        """Each kind's distance from the main window's picked vertex."""
        vertex = self.main.picked
        for item, scene, title in zip(self.items, self.scenes, self.titles, strict=True):
            scene.show_marker(vertex)
            d = self.main.distance_map(item) if vertex is not None else None
            if d is None:
                title.setText(f"{LABELS[item]}: pick a vertex / compute the spectrum")
                continue
            if self.main.distance_display == "threshold":
                thr = self.main.threshold_fraction * float(d.max())
                scene.show_field((d > thr).astype(float), "threshold", name=LABELS[item])
            else:
                scene.show_field(d, "sequential", name=LABELS[item])
            title.setText(f"{LABELS[item]} from vertex {vertex}")
        self.render_all()

    def refresh(self) -> None:
        if self.distances:
            self.show_distance()
        else:
            self.show_mode(self.main.mode_index)

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
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".png", dir=path.parent)
        os.close(fd)
        try:
            Image.fromarray(canvas).save(tmp, format="PNG")
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return path

    def closeEvent(self, event):  # noqa: N802
        for viewport in self.viewports:
            viewport.close_plotter()
        if self.main.compare is self:
            self.main.compare = None
        super().closeEvent(event)
