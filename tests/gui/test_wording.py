"""Wording of the viewer's dialogs: files named, defaults that do what was asked for,
one default threshold share everywhere."""

import pytest

from modalviewer.core.primitives import icosphere
from modalviewer.viewer.state import DEFAULT_THRESHOLD_SHARE


def _write_points(path, n):
    path.write_text("".join(f"v {i} {i % 2} {i % 3}\n" for i in range(n)))
    return path


def test_a_point_cloud_dialog_names_the_file(window, tmp_path):
    path = _write_points(tmp_path / "scan_points.obj", 5)
    assert window.open_mesh(path) is False
    assert window.last_error.startswith("scan_points.obj: ")
    assert "no faces" in window.last_error and "point cloud" in window.last_error


def test_a_point_cloud_as_the_second_mesh_names_the_file(window, tmp_path):
    window.set_mesh(icosphere(2))
    path = _write_points(tmp_path / "second_points.obj", 4)
    assert window.open_second_mesh(path, wait=False) is None
    assert window.last_error.startswith("second_points.obj: ")


def test_compare_asks_with_yes_as_the_default(window, qtbot, answer_next_dialog):
    window.set_mesh(icosphere(2))
    asked = answer_next_dialog(200)  # the real question, answered by Enter
    assert window.open_comparison(["laplacian", "modified_dirichlet"], wait=False) is None
    assert asked["title"] == "Compare" and "Compute now?" in asked["text"]
    assert asked["default"] == "Yes"
    # Enter said yes: the spectra are computed and the comparison opens
    qtbot.waitUntil(lambda: window.compare is not None, timeout=120000)


def test_compare_marks_the_default_threshold_share_without_a_main_map(window):
    assert DEFAULT_THRESHOLD_SHARE == pytest.approx(0.1)
    window.set_mesh(icosphere(3))
    assert window.state.display.threshold_share == DEFAULT_THRESHOLD_SHARE
    # compare: the main window's distance map is not computed (vibration, no shells),
    # so the views mark the default share, not a fraction of their largest distance
    window.state.set_pick(7)
    window.state.set_display(distance_kind="vibration", distance_display="threshold")
    assert window.state.derived.marked_share() is None
    compare = window.open_comparison(["hks", "feature"])
    for title in compare.titles:
        marked = float(title.text().split("(")[-1].split("%")[0])
        assert marked == pytest.approx(100 * DEFAULT_THRESHOLD_SHARE, abs=0.5), title.text()


def test_the_pair_starts_at_the_main_windows_default_share(tmp_path):
    from modalviewer.core.cache import SpectrumCache
    from modalviewer.viewer.jobs import JobQueue
    from modalviewer.viewer.pair import PairState

    sphere = icosphere(2)
    pair = PairState(JobQueue(), SpectrumCache(tmp_path), sphere, sphere, k=10)
    assert pair.share == DEFAULT_THRESHOLD_SHARE  # was 0.05 against the main window's 0.1


def test_a_continuous_map_names_the_share_its_threshold_map_will_mark(window, spot_path):
    """Under Xvfb: with the continuous map on screen the threshold label read "(73.0 % of
    surface)" (the default fraction 0.2 of the largest distance), and switching to the
    threshold display then marked 10 %: the label now says what the threshold map marks."""
    window.open_mesh(spot_path)
    window.compute("laplacian", k=20, wait=True)
    window.state.set_display(distance_kind="hks")
    window.pick_vertex(1008)
    assert window.state.display.distance_display == "continuous"
    label = window.distances_panel.threshold_label.text()
    assert "(10.0 % of surface)" in label, label
    window.show_distance(display="threshold")
    assert "(10.0 % of surface)" in window.distances_panel.threshold_label.text()
