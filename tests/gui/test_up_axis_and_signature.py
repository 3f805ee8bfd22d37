"""View > Up axis (remembered per file, R keeps it) and the Distances panel's typed
scale, log colours and exact signature curve."""

from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import torus
from modalviewer.core.signatures import default_times, signature

pytestmark = pytest.mark.gui
ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture
def z_up_cow(tmp_path):
    mesh = mv.load_mesh(ASSETS / "spot.obj")
    v = mesh.vertices
    v = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])
    path = tmp_path / "spot_z_up.obj"
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def _up(win):
    return np.asarray(win.viewer.current_camera()["view_up"])


def test_the_up_axis_menu_turns_the_view_and_is_remembered_per_file(qtbot, z_up_cow):
    from modalviewer.gui import MainWindow

    first = MainWindow(remember_settings=True)
    qtbot.addWidget(first)
    first.open_mesh(z_up_cow)
    actions = first.up_axis_actions
    assert actions[None].isChecked() and "(+Z)" in actions[None].text()
    assert _up(first)[2] > 0.9  # detected: standing upright
    actions["+y"].trigger()
    assert first.state.up_axis == "+y" and actions["+y"].isChecked()
    assert _up(first)[1] > 0.9
    first.plotter.camera.Azimuth(70)
    first.scene_view.drawing.reset_camera()  # R: the canonical view for the chosen axis
    assert _up(first)[1] > 0.9
    first.open_mesh(ASSETS / "demo_plate.obj")  # another file: automatic
    assert first.state.up_axis is None and actions[None].isChecked()
    first.close()
    second = MainWindow(remember_settings=True)
    qtbot.addWidget(second)
    second.open_mesh(z_up_cow)
    assert second.state.up_axis == "+y" and second.up_axis_actions["+y"].isChecked()
    assert _up(second)[1] > 0.9
    second.up_axis_actions[None].trigger()  # back to automatic, forgotten
    assert second.state.up_axis is None and _up(second)[2] > 0.9
    second.close()
    third = MainWindow(remember_settings=True)
    qtbot.addWidget(third)
    third.open_mesh(z_up_cow)
    assert third.state.up_axis is None
    third.close()


def test_typed_scale_log_colours_and_the_exact_curve(window, qtbot):
    state, panel = window.state, window.distances_panel
    window.set_mesh(torus(16, 8))
    state.set_display(distance_kind="feature")
    spec = window.compute("modified_dirichlet", k=20, wait=True)
    times = default_times(spec)
    t = float(np.sqrt(times[20] * times[21]))
    panel.scale_edit.setText(f"{t!r}")
    panel.scale_edit.editingFinished.emit()
    assert state.display.kind == "signature" and state.display.signature_time == t
    assert panel.scale_slider.value() in (20, 21)
    np.testing.assert_allclose(state.derived.field().values, signature(spec, [t])[1][:, 0])
    panel.log_check.setChecked(True)
    assert state.style.log_signature and "log10" in window.status_line.text()
    panel.scale_slider.setValue(40)  # a sample replaces the typed scale
    assert state.display.signature_time is None
    assert panel.scale_edit.text() == f"{times[40]:.4g}"
    # scales far below the default ones: the truncated curve misses a lot, and the
    # curve over all modes comes from a job, drawn dashed beside it
    state.set_scale_range((0.02 * times[0], times[-1]))
    window.viewer.pick_vertex(5)
    qtbot.waitUntil(lambda: state.derived.exact_curve() is not None, timeout=30000)
    qtbot.waitUntil(lambda: panel.signature_plot.second is not None, timeout=5000)
    exact = mv.local_signature(
        torus(16, 8), "modified_dirichlet", [5], state.derived.table("modified_dirichlet").times
    )[0]
    np.testing.assert_allclose(panel.signature_plot.second, exact, rtol=1e-6)
    assert np.all(panel.signature_plot.second >= panel.signature_plot.y - 1e-12)


def test_the_distances_panel_offers_the_wave_kernel_distance_over_energies(window):
    state, panel = window.state, window.distances_panel
    window.set_mesh(torus(16, 8))
    spec = window.compute("laplacian", k=20, wait=True)
    window.viewer.pick_vertex(3)
    form = panel.layout()
    assert form.labelForField(panel.t1_edit).text() == "t1"
    panel.kind_combo.setCurrentIndex(panel.kind_combo.findData("wks"))
    assert state.display.distance_kind == "wks"
    assert form.labelForField(panel.t1_edit).text() == "E1"
    assert form.labelForField(panel.scale_row).text() == "E"
    energies = mv.default_energies(spec)
    assert panel.t1_edit.placeholderText() == f"default {energies[0]:.4g}"
    assert panel.signature_plot.xlabel == "E (log)"
    _, w = mv.signature(spec, kind="wks", energies=energies, vertices=[3])
    np.testing.assert_allclose(panel.signature_plot.y, w[0], rtol=1e-12)
    panel.kind_combo.setCurrentIndex(panel.kind_combo.findData("hks"))
    assert form.labelForField(panel.t1_edit).text() == "t1"


def test_the_compute_panel_suggests_the_robust_laplacian_on_slivers(window):
    from benchmarks.slivers import add_slivers
    from modalviewer.core.primitives import icosphere

    pytest.importorskip("robust_laplacian")
    panel = window.compute_panel
    window.set_mesh(icosphere(3))
    assert "negative cotan" not in panel.mesh_info.text()
    v, f = add_slivers(icosphere(3), needles=20, caps=20, eps=1e-8, seed=2)
    window.set_mesh(mv.Mesh(v, f))
    assert "This mesh has 46 negative cotan weights: try the Laplacian (robust" in (
        panel.mesh_info.text()
    )
    assert panel.operator_combo.findData("laplacian_robust") >= 0
