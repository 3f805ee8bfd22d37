"""The wave kernel distance and signature in the viewer (without a window), the CLI's
``--kind wks``, a batch store's wks signature, and the Distances panel's words for it."""

from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer import cli
from modalviewer.core.primitives import torus
from modalviewer.core.signatures import wks_sigma
from modalviewer.viewer import Viewer, wording

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture
def viewer():
    v = Viewer()
    v.set_mesh(torus(16, 8))
    v.compute("laplacian", k=30)
    yield v
    v.close()


def test_the_viewer_shows_the_wave_kernel_distance_and_signature(viewer):
    state = viewer.state
    spec = state.spectrum("laplacian")
    state.set_scale_range((0.05, 2.0))  # scales t of the heat kernel
    viewer.pick_vertex(7)
    viewer.show_distance("hks", display="continuous")
    assert state.t_range == (0.05, 2.0)
    viewer.show_distance("wks", display="continuous")
    # a range of times t does not carry over to energies E
    assert state.t_range is None
    field = state.derived.field()
    np.testing.assert_allclose(
        field.values, mv.multiscale_distance(spec, 7, kind="wks"), rtol=1e-12, atol=1e-15
    )
    assert field.title.startswith("Wave kernel distance")
    energies = mv.default_energies(spec)
    assert f"energies E = {energies[0]:.3g} .. {energies[-1]:.3g}" in field.legend
    viewer.show_signature(40)
    field = state.derived.field()
    _, expected = mv.signature(spec, kind="wks", energies=energies[[40]], sigma=wks_sigma(energies))
    np.testing.assert_allclose(field.values, expected[:, 0], rtol=1e-12)
    assert f"Wave kernel signature at E = {energies[40]:.3g}" in wording.legend(state)
    assert state.derived.truncation() is None and state.derived.curve_key() is None
    # a typed energy range
    state.set_scale_range((energies[5], energies[60]))
    viewer.show_distance("wks", display="continuous")
    np.testing.assert_allclose(
        state.derived.field().values,
        mv.multiscale_distance(spec, 7, t_range=(energies[5], energies[60]), kind="wks"),
        rtol=1e-12,
        atol=1e-15,
    )


def test_cli_distance_kind_wks_writes_the_library_distance(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    csv = tmp_path / "d.csv"
    path = ASSETS / "demo_plate.obj"
    args = ["distance", str(path), "--vertex", "3", "--kind", "wks", "-k", "20", "--csv", str(csv)]
    assert cli.main(args) == 0
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    mesh = mv.load_mesh(path)
    spec = mv.compute_spectrum(mesh, "laplacian", k=20)
    expected = mv.multiscale_distance(spec, 3, kind="wks")
    np.testing.assert_allclose(rows[:, 1], expected, rtol=1e-6, atol=1e-9 * expected.max())
    assert "wks distance from vertex 3" in capsys.readouterr().out
    # a mesh against itself: the wave kernel distance to B is the one on A
    csv_to = tmp_path / "to.csv"
    args = ["distance", str(path), "--vertex", "3", "--kind", "wks", "--to", str(path)]
    assert cli.main([*args, "-k", "20", "--csv", str(csv_to)]) == 0
    rows = np.loadtxt(csv_to, delimiter=",", skiprows=1)
    np.testing.assert_allclose(rows[:, 1], expected, rtol=1e-6, atol=1e-6 * expected.max())


def test_a_batch_store_keeps_the_wks_signature(tmp_path):
    from modalviewer.collection import process_mesh

    parameters = {
        "operator": "laplacian",
        "k": 20,
        "bending": 1.0,
        "membrane": 1.0,
        "signatures": ["wks"],
    }
    path = tmp_path / "torus.obj"
    t = torus(12, 6)
    path.write_text(
        "".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in t.vertices)
        + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in t.faces)
    )
    result = process_mesh(str(path), parameters)
    assert result["status"] == "computed", result
    arrays = result["arrays"]
    spec = mv.compute_spectrum(mv.load_mesh(path), "laplacian", k=20)
    energies, values = mv.signature(spec, kind="wks")
    np.testing.assert_allclose(arrays["sig.wks.times"], energies, rtol=1e-8)
    np.testing.assert_allclose(arrays["sig.wks.values"], values, rtol=1e-6, atol=1e-9)
