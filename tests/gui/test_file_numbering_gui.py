"""Issue 25 in the window: picks by the file's number, labels and field exports in it."""

import numpy as np

from modalviewer.core.primitives import icosphere


def test_the_window_picks_and_exports_in_file_numbers(window, tmp_path):
    import pyvista as pv

    base = icosphere(2)
    n = base.n_vertices
    v = np.vstack([[[5.0, 5.0, 5.0]], base.vertices, [[6.0, 6.0, 6.0]]])  # unused 0, n + 1
    path = tmp_path / "padded.ply"
    head = f"ply\nformat ascii 1.0\nelement vertex {len(v)}\n"
    head += "property double x\nproperty double y\nproperty double z\n"
    head += f"element face {base.n_faces}\nproperty list uchar int vertex_indices\nend_header\n"
    rows = [f"{x:.17g} {y:.17g} {z:.17g}" for x, y, z in v]
    rows += [f"3 {a} {b} {c}" for a, b, c in base.faces + 1]
    path.write_text(head + "\n".join(rows) + "\n")
    window.open_mesh(path)
    window.compute("laplacian", k=20, wait=True)
    window.pick_file_vertex(41)
    assert window.picked == 40 and window.state.picked_file_vertex == 41
    assert window.distances_panel.pick_label.text().startswith("Picked vertex 41 at")
    window.pick_file_vertex(n + 1)  # used by no face: a message, the pick stays
    assert window.picked == 40
    window.show_distance("hks")
    out = window.export_field(tmp_path / "f.vtp")
    np.testing.assert_array_equal(pv.read(out).point_data["file_vertex"], np.arange(1, n + 1))
