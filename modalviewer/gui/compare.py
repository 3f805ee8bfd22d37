"""Side-by-side views with one shared camera: operators (Fig. 1) or distance kinds (Figs. 6, 7).

Each view draws its own :class:`MeshScene` of the main window's mesh, as the
:class:`~modalviewer.viewer.comparison.Comparison` says, and all renderers share one VTK
camera, so rotating one rotates all.  The views follow the main window's state and
never change it.
"""

from __future__ import annotations

from qtpy import QtWidgets

from ..scene.mesh_scene import MeshScene
from ..scene.view import draw_field, label_field
from ..viewer.comparison import Comparison, item_label
from .viewport import make_viewport
from .views_window import ViewsWindow


class CompareWindow(ViewsWindow):
    """Two or three linked views of ``items`` (operators or distance kinds).  Operator
    views share the comparison's mode index, starting at the first non-zero mode; Left /
    Right step it, Esc and Ctrl+W close the window."""

    EXPORT = ("compare.png", "Export the comparison")

    def __init__(self, main, items: list[str], force_offscreen: bool | None = None):
        super().__init__()
        self.main = main
        self.state = main.state
        self.comparison = Comparison(self.state, items)
        self.setWindowTitle("modalviewer - " + self.comparison.title)
        layout = QtWidgets.QHBoxLayout(self)
        self.viewports, self.scenes, self.titles = [], [], []
        camera = None
        for item in self.comparison.items:
            column = QtWidgets.QVBoxLayout()
            title = QtWidgets.QLabel(item_label(item))
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
            viewport.cameraChanged.connect(self.render_all)
            self.viewports.append(viewport)
            self.scenes.append(scene)
            self.titles.append(title)
        for event in self._followed():  # also a spectrum replaced (another k, weights)
            event.connect(self.refresh)
        self.install_keys(
            [
                ("Escape", self.close),
                ("Ctrl+W", self.close),
                ("Right", lambda: self.comparison.step(+1)),
                ("Left", lambda: self.comparison.step(-1)),
            ]
        )
        self.resize(420 * len(items), 480)

    def _followed(self) -> tuple:
        """The events the views are redrawn on."""
        events = self.state.events
        return events.pick, events.display, events.style, events.spectra, self.comparison.changed

    def refresh(self) -> None:
        """Draw what the comparison's views show now."""
        views = self.comparison.views()
        for view, scene, title in zip(views, self.scenes, self.titles, strict=True):
            title.setText(view.title)
            if self.comparison.distances:
                scene.show_marker(view.marker)
            if view.field is not None or self.comparison.distances:
                draw_field(scene, view.field)
                label_field(scene, view.field)
        self.render_all()

    def captions(self) -> list[str]:
        return [title.text() for title in self.titles]

    def closeEvent(self, event):  # noqa: N802
        for followed in self._followed():
            followed.disconnect(self.refresh)
        self.close_views()
        if self.main.compare is self:
            self.main.compare = None
        super().closeEvent(event)
