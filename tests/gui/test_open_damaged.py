"""A damaged file in the viewer: named with the place of the damage, and "Open anyway"
(the default button) loads its whole records with a report of what was dropped."""

import numpy as np

from modalviewer.core.primitives import grid_plate


def _truncated_ply(path):
    plate = grid_plate(8, 8)
    header = (
        f"ply\nformat binary_little_endian 1.0\nelement vertex {plate.n_vertices}\n"
        "property double x\nproperty double y\nproperty double z\n"
        f"element face {plate.n_faces}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()
    row = np.dtype([("n", "u1"), ("i", "<i4", 3)])
    faces = np.zeros(plate.n_faces, row)
    faces["n"], faces["i"] = 3, plate.faces
    data = header + np.asarray(plate.vertices, "<f8").tobytes() + faces.tobytes()
    cut = len(data) - 30 * row.itemsize - 5  # 31 faces lost, the last one mid-record
    path.write_bytes(data[:cut])
    return path, plate.n_faces


def test_a_damaged_file_is_named_and_not_loaded_without_asking(window, tmp_path):
    path, n_faces = _truncated_ply(tmp_path / "cut_scan.ply")
    assert window.open_mesh(path) is False
    assert window.state.mesh is None
    assert window.last_error.startswith("cut_scan.ply: element 'face' ")
    assert f"of the {n_faces}" in window.last_error


def test_open_anyway_is_the_default_and_loads_the_whole_records(
    window, answer_next_dialog, tmp_path
):
    path, n_faces = _truncated_ply(tmp_path / "cut_scan.ply")
    asked = answer_next_dialog(300)  # the real dialog, answered by Enter
    assert window.open_mesh(path) is True
    assert asked["title"] == "Damaged file" and asked["default"] == "Open anyway"
    assert "cut_scan.ply" in asked["text"]
    mesh = window.state.mesh
    assert mesh.n_faces == n_faces - 31
    report = str(mesh.report)
    assert f"the file ends in face element {n_faces - 31} of the {n_faces}" in report


def test_a_damaged_second_mesh_is_named_and_open_anyway_loads_it(window, monkeypatch, tmp_path):
    from modalviewer.core.primitives import icosphere

    window.set_mesh(icosphere(2))
    path, n_faces = _truncated_ply(tmp_path / "cut_second.ply")
    assert window.open_second_mesh(path, wait=False) is None
    assert window.last_error.startswith("cut_second.ply: element 'face' ")
    monkeypatch.setenv("MODALVIEWER_ASSUME_YES", "1")  # the dialog's answer: Open anyway
    pair = window.open_second_mesh(path, wait=False)
    assert pair is not None
    assert pair.pair.mesh("b").n_faces == n_faces - 31
    pair.close()


def test_a_run_without_a_display_refuses_a_damaged_file_instead_of_waiting(tmp_path):
    # nobody can answer "Open anyway" off screen: the run refuses the file at once and
    # names --partial, which opens its whole records
    import os
    import subprocess
    import sys

    path, n_faces = _truncated_ply(tmp_path / "cut_scan.ply")
    out = tmp_path / "shot.png"
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", MODALVIEWER_CACHE=str(tmp_path / "c"))
    env.pop("MODALVIEWER_NO_DIALOGS", None)
    command = [sys.executable, "-m", "modalviewer", str(path), "--operator", "laplacian"]
    command += ["-k", "8", "--screenshot", str(out)]
    run = subprocess.run(command, capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 1
    assert "modalviewer: error: cut_scan.ply: element 'face' " in run.stderr
    assert "the file is damaged or truncated" in run.stderr
    assert "note: --partial opens the file's whole records" in run.stderr
    assert not out.exists()
    run = subprocess.run(
        command + ["--partial"], capture_output=True, text=True, env=env, timeout=120
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert f"{n_faces - 31} faces" in run.stdout  # the report of what was loaded
    assert out.stat().st_size > 1000
    # Qt's off-screen platform's notice for each window shown is not printed
    assert "propagateSizeHints" not in run.stderr, run.stderr
