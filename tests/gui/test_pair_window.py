"""The shape pair window: spot as A, spot rigidly moved as B; picks by click and by script,
threshold and marker pixels in the export, linked and free cameras."""

from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image
from qtpy import QtCore

import modalviewer as mv
from modalviewer.core.laplacian import vertex_normals
from modalviewer.viewer.camera import Camera

pytestmark = pytest.mark.gui


@pytest.fixture
def moved_spot(spot_path, tmp_path) -> Path:
    mesh = mv.load_mesh(spot_path)
    q, _ = np.linalg.qr(np.random.default_rng(5).normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    path = tmp_path / "moved_spot.obj"
    trimesh.Trimesh(mesh.vertices @ q.T + [2.0, -1.0, 0.5], mesh.faces, process=False).export(path)
    return path


def _click(qtbot, widget, pos):
    qtbot.mouseClick(widget, QtCore.Qt.MouseButton.LeftButton, pos=pos)


def _drag(qtbot, widget, dx):
    start = QtCore.QPoint(widget.width() // 2, widget.height() // 2)
    qtbot.mousePress(widget, QtCore.Qt.MouseButton.LeftButton, pos=start)
    for step in range(1, 6):
        qtbot.mouseMove(widget, start + QtCore.QPoint(dx * step // 5, 0))
    qtbot.mouseRelease(widget, QtCore.Qt.MouseButton.LeftButton, pos=start + QtCore.QPoint(dx, 0))


def _blue(img):  # the threshold's SIMILAR_BLUE (51, 115, 217), shaded
    r, g, b = (img[..., i].astype(int) for i in range(3))
    return (b > 120) & (b - r > 80) & (b - g > 40)


def _magenta(img):  # the marker (230, 26, 153), shaded
    r, g, b = (img[..., i].astype(int) for i in range(3))
    return (r > 110) & (r - g > 80) & (b - g > 40) & (r > b)


def test_pick_on_a_shows_the_distance_and_best_match_on_b(
    window, spot_path, moved_spot, tmp_path, qtbot, display_position
):
    window.open_mesh(spot_path)
    window.state.set_display(distance_kind="hks")  # the pair starts with the main's kind
    pair = window.open_second_mesh(moved_spot, k=20)
    assert window.pair_window is pair and pair.pair.kind == "hks" and pair.pair.ready()
    assert pair.pair.rescale and "scale covariant" in pair.rescale_check.toolTip()
    # a click in the middle of A picks a vertex of A that faces the viewer
    a_view = pair.viewports["a"].widget
    _click(qtbot, a_view, QtCore.QPoint(a_view.width() // 2, a_view.height() // 2))
    assert pair.pair.picked is not None and pair.pair.picked[0] == "a"
    v = pair.pair.picked[1]
    d = pair.pair.distance_on("b")
    assert d[v] <= 1e-8 * d.max()  # the moved copy of the pick: distance zero
    side, w, dist = pair.pair.best_match()
    assert (side, w) == ("b", v) and dist <= 1e-8 * d.max()
    assert pair.pair.back_match() == v  # mutual
    field = np.array(pair.scenes["b"].surface.point_data["field"])
    np.testing.assert_allclose(field, d, rtol=0, atol=1e-12 * d.max())
    assert "best match: vertex" in pair.scenes["b"].legend_text
    assert window.state.picked is None and window.state.display.kind == "none"  # untouched

    # look at the match on B from outside along its normal; the linked A turns with it
    mesh_b = pair.pair.mesh("b")
    normal = vertex_normals(mesh_b)[w]
    point = mesh_b.vertices[w]
    up = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(up) < 0.1:
        up = np.cross(normal, [0.0, 1.0, 0.0])
    a_before = np.array(pair.viewports["a"].plotter.camera.GetPosition())
    pair.scenes["b"].set_camera(
        Camera(tuple(point + 2.5 * normal), tuple(point), tuple(up / np.linalg.norm(up))),
        fit=False,
    )
    pair._on_camera("b")
    assert np.linalg.norm(pair.viewports["a"].plotter.camera.GetPosition() - a_before) > 0.1

    pair.pair.set_display("threshold", share=0.05)
    legend = pair.scenes["b"].legend_text
    assert "blue: heat kernel distance < " in legend and "% of B" in legend
    out = pair.export_screenshot(tmp_path / "pair.png")
    assert [p.name for p in tmp_path.glob(".pair.png*")] == []  # no temporary file left
    img = np.asarray(Image.open(out).convert("RGB"))
    half = img.shape[1] // 2
    left, right = img[:, :half], img[:, half:]
    # B: a blue region around the match (5 % of its area) and the marker at the match;
    # A: no distance map (plain grey)
    assert _blue(right).sum() > 1500, _blue(right).sum()
    assert _blue(left).sum() < 50
    assert _magenta(right).sum() > 30
    # the marker on B sits where the match projects
    x, y, _ = display_position(pair.scenes["b"], w)
    h = right.shape[0]
    ys, xs = np.nonzero(_magenta(right))
    assert np.min(np.hypot(xs - x, ys - (h - 1 - y))) < 6
    # moving the threshold recolours B only (A's picture is unchanged)
    renders_a = pair.viewports["a"].render_count
    pair.share_slider.setValue(200)  # 20 %
    assert pair.pair.share == pytest.approx(0.2)
    assert pair.scenes["b"].threshold == pytest.approx(pair.pair.view("b").threshold)
    assert "20.0 % of B" in pair.scenes["b"].legend_text
    assert pair.viewports["a"].render_count == renders_a
    big = pair.export_screenshot(tmp_path / "pair2.png", scale=2, transparent=True)
    big_img = Image.open(big)
    assert big_img.mode == "RGBA" and big_img.size[0] >= 2 * img.shape[1] - 8

    # a click on B works the other way
    pair.pair.pick("b", 123)  # the window computes what the pick needs
    d_a = pair.pair.distance_on("a")
    assert pair.pair.distance_on("b") is None and d_a[123] <= 1e-8 * d_a.max()
    assert pair.pair.best_match()[:2] == ("a", 123)

    # free cameras: turning A leaves B where it is; linked again, B follows
    pair.link_check.setChecked(False)
    b_before = np.array(pair.viewports["b"].plotter.camera.GetPosition())
    _drag(qtbot, a_view, 80)
    assert np.allclose(pair.viewports["b"].plotter.camera.GetPosition(), b_before)
    pair.link_check.setChecked(True)
    _drag(qtbot, a_view, 80)
    assert not np.allclose(pair.viewports["b"].plotter.camera.GetPosition(), b_before)
    assert pair.pair.picked == ("b", 123)  # drags are not clicks

    pair.close()
    assert window.pair_window is None


def test_open_second_mesh_reports_a_bad_file(window, spot_path, tmp_path):
    from modalviewer.gui.pair_window import PairError

    window.open_mesh(spot_path)
    bad = tmp_path / "bad.obj"
    bad.write_text("this is not a mesh\n")
    with pytest.raises(PairError):
        window.open_second_mesh(bad)
    assert window.last_error and getattr(window, "pair_window", None) is None


def test_pair_window_keys_esc_cancels_first_then_closes(window, spot_path, moved_spot, qtbot):
    """Found under Xvfb: Esc during the pair's computation cancelled it and also closed
    the window (pick and cameras lost), and R / Ctrl+W did nothing once a 3D view had
    the focus.  The keys are window shortcuts now (one table with keyPressEvent), and Esc
    cancels while something runs, closing only when nothing does."""
    window.open_mesh(spot_path)
    pair = window.open_second_mesh(moved_spot, wait=False, k=20)
    qtbot.waitUntil(lambda: bool(pair.pair.pending()), timeout=5000)
    qtbot.keyClick(pair, QtCore.Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: not pair.pair.pending(), timeout=20000)
    assert pair.isVisible()  # cancelled, still open
    cam = pair.viewports["a"].plotter.camera
    cam.Azimuth(40)
    before = cam.GetPosition()
    qtbot.keyClick(pair, QtCore.Qt.Key.Key_R)
    assert cam.GetPosition() != before  # the cameras went back
    qtbot.keyClick(pair, QtCore.Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: not pair.isVisible(), timeout=2000)


def test_pair_export_dialog_offers_size_and_transparency(
    window, spot_path, moved_spot, tmp_path, monkeypatch
):
    """Found under Xvfb: the pair's Export opened a bare file dialog in the working folder,
    without the size multiplier or transparent background of the main export."""
    from modalviewer.gui import dialogs

    window.open_mesh(spot_path)
    pair = window.open_second_mesh(moved_spot, k=20)
    seen = {}

    def accept(dialog):
        seen["start"] = dialog.path_edit.text()
        seen["colorbar_shown"] = dialog.colorbar.isVisibleTo(dialog)
        dialog.path_edit.setText(str(tmp_path / "pair2x.png"))
        dialog.scale.setValue(2)
        dialog.transparent.setChecked(True)
        return dialogs.QtWidgets.QDialog.DialogCode.Accepted

    monkeypatch.setattr(dialogs.ScreenshotDialog, "exec", accept)
    pair.export_dialog()
    assert seen["start"] == str(spot_path.resolve().parent / "pair.png")
    assert not seen["colorbar_shown"]
    out = tmp_path / "pair2x.png"
    assert out.is_file() and "Saved" in pair.status.text()
    one = pair.export_screenshot(tmp_path / "pair1x.png")
    from PIL import Image

    big, small = Image.open(out), Image.open(one)
    assert big.mode == "RGBA" and small.mode == "RGB"
    assert abs(big.width - 2 * small.width) <= 8 and big.height == 2 * small.height


def test_the_pairs_progress_text_fits_its_bar(window, spot_path, moved_spot, qtbot):
    """A newcomer found the pair's progress text cut off inside its bar (the
    computation's long name, stage and percentage); the name is shortened with an
    ellipsis and the stage and percentage always show."""
    window.open_mesh(spot_path)
    window.state.set_display(distance_kind="vibration")
    pair = window.open_second_mesh(moved_spot, wait=False, k=20)
    seen = []

    def text_fits():
        bar = pair.job_progress.bar
        if bar.isVisible() and "%" in bar.text():
            seen.append((bar.text(), bar.fontMetrics().horizontalAdvance(bar.text()), bar.width()))
        return bool(seen)

    qtbot.waitUntil(text_fits, timeout=20000)
    pair.pair.cancel()
    text, width, room = seen[0]
    assert width <= room - 8, seen[0]
    assert text.rstrip(")").split(" (+")[0].endswith(" %"), text  # the percentage shows
    qtbot.waitUntil(lambda: not pair.pair.pending(), timeout=20000)
