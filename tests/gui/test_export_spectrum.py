"""File > Export spectrum writes the spectrum the picture on screen is made of
(``Viewer.spectrum_shown``)."""

from pathlib import Path

from modalviewer.core.cache import SpectrumCache
from modalviewer.viewer import Viewer

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def test_the_exported_spectrum_is_the_one_on_screen(tmp_path):
    # with a vibration distance on screen and the Laplacian computed after it (as the
    # distance comparison does), the export took the Laplacian
    model = Viewer(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(ASSETS / "demo_plate.obj")
    state = model.state
    model.jobs.wait(model.request_spectrum("shells", k=12, show=True))
    state.show_mode(8)
    assert model.spectrum_shown().operator == "shells"
    state.set_display(kind="distance", distance_kind="vibration")
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=False))
    assert model.spectrum_shown().operator == "shells"
    state.set_display(distance_kind="hks")
    assert model.spectrum_shown().operator == "laplacian"
    state.show_mode(3, "laplacian")
    assert model.spectrum_shown().operator == "laplacian"


def test_the_exported_spectrum_has_a_row_per_vertex_of_the_file(tmp_path):
    import numpy as np

    import modalviewer as mv

    plate = mv.load_mesh(ASSETS / "demo_plate.obj")
    v = np.vstack([[[9.0, 9.0, 9.0]], plate.vertices])  # vertex 0 used by no face
    path = tmp_path / "padded.obj"
    rows = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in v]
    path.write_text("\n".join(rows + [f"f {a + 2} {b + 2} {c + 2}" for a, b, c in plate.faces]))
    model = Viewer(cache=SpectrumCache(tmp_path / "cache"))
    mesh = model.open_mesh(path)
    model.jobs.wait(model.request_spectrum("laplacian", k=8, show=True))
    spec = model.spectrum_shown()
    mv.save_spectrum(spec, tmp_path / "s.npz")
    back = mv.load_spectrum(tmp_path / "s.npz", mesh=mesh)  # the file's mesh, as loaded
    assert back.n_vertices == len(v) and np.isnan(back.modes[0]).all()
    np.testing.assert_allclose(
        back.modes[1:], mv.compute_spectrum(plate, "laplacian", k=8).modes, atol=1e-10
    )
