"""500 random actions on the real window: no unhandled exception, no hang."""

import sys

import numpy as np
import pytest
from qtpy import QtCore

pytestmark = pytest.mark.gui


def test_random_actions(window, qtbot, tmp_path, spot_path):
    from modalviewer.core.primitives import grid_plate, icosphere

    corpus = [
        spot_path,
        tmp_path / "plate.obj",
        tmp_path / "sphere.ply",
        tmp_path / "empty.obj",
        tmp_path / "junk.stl",
    ]
    import trimesh

    plate = grid_plate(12, 8)
    trimesh.Trimesh(plate.vertices, plate.faces, process=False).export(corpus[1])
    sphere = icosphere(3)
    trimesh.Trimesh(sphere.vertices, sphere.faces, process=False).export(corpus[2])
    corpus[3].write_text("")
    corpus[4].write_bytes(np.random.default_rng(1).bytes(2000))

    errors = []
    old_hook = sys.excepthook
    sys.excepthook = lambda *exc: errors.append(exc)
    rng = np.random.default_rng(2024)
    operators = ["laplacian", "modified_dirichlet", "shells", "shells_normal"]

    def act(name):
        if window.mesh is None and name not in ("open",):
            name = "open"
        if name == "open":
            window.open_mesh(corpus[rng.integers(len(corpus))])
        elif name == "compute":
            window.compute(operators[rng.integers(4)], k=int(rng.integers(2, 25)), wait=False)
        elif name == "cancel":
            window.cancel_computation()
        elif name == "operator":
            window.compute_panel.operator_combo.setCurrentIndex(int(rng.integers(4)))
        elif name == "mode":
            window.modes_panel.mode_spin.setValue(int(rng.integers(0, 30)))
        elif name == "pick":
            window.pick_vertex(int(rng.integers(0, window.mesh.n_vertices)))
        elif name == "click":
            w = window.viewport.widget
            pos = QtCore.QPoint(int(rng.integers(w.width())), int(rng.integers(w.height())))
            qtbot.mouseClick(w, QtCore.Qt.MouseButton.LeftButton, pos=pos)
        elif name == "threshold":
            window.distances_panel.threshold_slider.setValue(int(rng.integers(1, 1000)))
        elif name == "display":
            window.distances_panel.display_combo.setCurrentIndex(int(rng.integers(2)))
        elif name == "kind":
            window.distances_panel.kind_combo.setCurrentIndex(int(rng.integers(3)))
        elif name == "animate":
            window.animation_panel.play_button.toggle()
        elif name == "isolines":
            window.modes_panel.iso_spin.setValue(int(rng.integers(0, 30)))
        elif name == "signature":
            window.distances_panel.scale_slider.setValue(int(rng.integers(0, 100)))
        elif name == "curvature":
            window.show_curvature()
        elif name == "export":
            window.export_screenshot(tmp_path / f"shot{rng.integers(3)}.png")
        elif name == "render":
            window.viewport.render_now()

    names = [
        "open",
        "compute",
        "cancel",
        "operator",
        "mode",
        "pick",
        "click",
        "threshold",
        "display",
        "kind",
        "animate",
        "isolines",
        "signature",
        "curvature",
        "export",
        "render",
    ]
    weights = np.array([3, 6, 2, 2, 6, 5, 4, 4, 2, 2, 2, 2, 2, 1, 1, 2], dtype=float)
    try:
        for _ in range(500):
            act(names[rng.choice(len(names), p=weights / weights.sum())])
            qtbot.wait(int(rng.integers(0, 15)))
        # let any running job finish or cancel, then the window still works
        window.cancel_all()
        qtbot.waitUntil(lambda: not window.busy, timeout=60000)
        assert window.open_mesh(spot_path)
        spec = window.compute("laplacian", k=8, wait=True)
        assert spec.k == 8
    finally:
        sys.excepthook = old_hook
    import traceback

    assert errors == [], "".join(traceback.format_exception(*errors[0]))[-3000:]
