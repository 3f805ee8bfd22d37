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
    window.pick_vertex(41)
    assert window.picked == 41 and window.state.picked_file_vertex == 41
    assert window.distances_panel.pick_label.text().startswith("Picked vertex 41 at")
    window.pick_vertex(n + 1)  # used by no face: a message, the pick stays
    assert window.picked == 41
    window.show_distance("hks")
    out = window.export_field(tmp_path / "f.vtp")
    exported = pv.read(out)  # one point per vertex of the file, in the file's order
    assert exported.n_points == len(v) and "file_vertex" not in exported.point_data
    values = np.asarray(exported.point_data[exported.point_data.keys()[0]])
    assert np.isnan(values[[0, n + 1]]).all() and np.isfinite(values[1 : n + 1]).all()
    assert values[41] == 0.0
