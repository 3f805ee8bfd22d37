"""The scripted flows of the window (tests/gui/test_state_sync.py) against a
:class:`modalviewer.viewer.Viewer` with no window.

``tests/test_headless.py`` runs this file again in a process where Qt cannot be
imported, so every flow here is known to need no Qt.  Pictures are drawn off screen
by the viewer's own scene and their pixels checked.
"""

from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.laplacian import lumped_masses
from modalviewer.viewer import ComputeError, Viewer, wording

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture
def spot_path():
    return ASSETS / "spot.obj"


@pytest.fixture
def viewer(tmp_path):
    v = Viewer(cache=mv.core.cache.SpectrumCache(tmp_path / "cache"))
    yield v
    v.close()


def _statuses(viewer) -> list[str]:
    """The status-line messages ``viewer`` emits from now on, as they come."""
    statuses = []
    viewer.events.status.connect(lambda text, _ms: statuses.append(text))
    return statuses


def _colours(img: np.ndarray) -> dict[str, int]:
    """Pixel counts of the paper's blue and orange (diverging ends, threshold blue)."""
    rgb = img[:, :, :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return {
        "blue": int(np.sum((b > r + 60) & (b > g + 20))),
        "orange": int(np.sum((r > b + 80) & (g > b + 20))),
    }


def test_a_waiting_compute_returns_its_own_spectrum(viewer, spot_path):
    """A request queued meanwhile keeps its turn and its own result."""
    viewer.open_mesh(spot_path)
    first = viewer.compute("shells", k=20, wait=False)
    assert first is None and viewer.jobs.busy
    spec = viewer.compute("laplacian", k=37)
    assert spec.operator == "laplacian" and spec.k == 37
    while viewer.jobs.busy:
        viewer.wait_for(viewer.jobs.running or viewer.jobs.jobs[0])
    assert viewer.spectra["shells"].k == 20


def test_a_mode_picture_is_the_mode_in_the_paper_colours(viewer, spot_path, tmp_path):
    viewer.open_mesh(spot_path)
    spec = viewer.compute("laplacian", k=12)
    residual = spec.residuals[~spec.zero_mode_mask()].max()
    assert residual < 1e-6
    viewer.show_mode(6)
    name, values = viewer.current_field()
    assert "mode 6" in name
    np.testing.assert_allclose(values, spec.mode(6), rtol=0, atol=1e-12)
    path = viewer.export_screenshot(tmp_path / "mode", size=(400, 300))
    assert path.suffix == ".png"
    from PIL import Image

    img = np.asarray(Image.open(path))
    assert img.shape[:2] == (300, 400)
    counts = _colours(img)
    assert counts["blue"] > 500 and counts["orange"] > 500, counts
    clear = viewer.image(transparent=True)
    assert clear.shape[2] == 4 and clear[0, -1, 3] == 0  # the background corner


def test_a_pick_shows_the_distance_and_the_share_it_marks(viewer, spot_path):
    viewer.open_mesh(spot_path)
    viewer.compute("modified_dirichlet", k=30)
    viewer.pick_vertex(1000)
    areas = lumped_masses(viewer.mesh)
    for share in (0.05, 0.2, 0.6):
        d = viewer.show_distance("feature", display="threshold", share=share)
        assert viewer.state.display.kind == "distance"
        expected = mv.multiscale_distance(viewer.spectra["modified_dirichlet"], 1000)
        np.testing.assert_allclose(d, expected, rtol=1e-10, atol=1e-12)
        thr = viewer.state.display.threshold * d.max()
        marked = areas[d <= thr].sum() / areas.sum()
        assert marked == pytest.approx(share, abs=0.01)
        assert f"{100 * marked:.1f} % of the surface" in wording.legend(viewer.state)
    # an absolute distance: the map marks exactly where d <= it
    d = viewer.show_distance(threshold=0.5 * d.max())
    assert viewer.state.display.threshold == pytest.approx(0.5)
    img = viewer.image(size=(400, 300))
    assert _colours(img)["blue"] > 1000


def test_a_comparison_never_changes_the_display(viewer, spot_path, tmp_path):
    viewer.open_mesh(spot_path)
    viewer.compute("modified_dirichlet", k=20)
    viewer.state.set_display(distance_kind="feature")
    viewer.pick_vertex(50)
    viewer.show_distance("feature", display="threshold", share=0.1)
    before = viewer.state.display
    compare = viewer.comparison(["laplacian", "modified_dirichlet"])
    assert "laplacian" in viewer.spectra and viewer.state.display == before
    assert compare.mode_index == 1  # the first non-zero mode, not the constant mode 0
    views = compare.views()
    assert views[0].title.startswith("Laplacian: mode 1,")
    assert np.ptp(views[0].field.values) > 0
    compare.step(+1)
    assert compare.mode_index == 2 and "mode 2," in compare.views()[1].title
    out = viewer.export_comparison(compare, tmp_path / "pair.png", size=(300, 300))
    from PIL import Image

    img = np.asarray(Image.open(out))
    assert img.shape[1] == 2 * 300 + 4
    with pytest.raises(ValueError, match="operators with operators"):
        viewer.comparison(["laplacian", "hks"])


def test_a_comparison_leaves_the_spectrum_of_a_distance_shown_current(viewer, spot_path):
    """A distance shown before any mode (its spectrum computed for it): a comparison that
    computes another spectrum leaves the current spectrum (the Modes panel's, the
    exported one) the distance's, not the first operator computed."""
    viewer.open_mesh(spot_path)
    viewer.pick_vertex(50, show=False)
    viewer.show_distance("feature", display="threshold", share=0.1)
    viewer.wait_for_modes(viewer.state.compute_settings.k, "modified_dirichlet")
    assert viewer.state.display.operator is None  # no mode shown yet
    assert viewer.state.current_operator() == "modified_dirichlet"
    viewer.comparison(["feature", "hks"])  # computes the Laplacian's spectrum
    assert set(viewer.spectra) >= {"laplacian", "modified_dirichlet"}
    assert viewer.state.current_operator() == "modified_dirichlet"
    assert viewer.spectrum_shown().operator == "modified_dirichlet"


def test_a_session_restores_the_same_picture(tmp_path, spot_path):
    cache = mv.core.cache.SpectrumCache(tmp_path / "cache")
    first = Viewer(cache=cache)
    first.open_mesh(spot_path)
    first.compute("modified_dirichlet", k=30)
    first.show_mode(7)
    first.state.style.isolines = 5
    first.pick_vertex(1234)
    first.show_distance("feature", display="threshold", share=0.25)
    image = first.image(size=(500, 400))
    name, values = first.current_field()
    session = first.save_session(tmp_path / "s.json")
    first.close()

    second = Viewer(cache=cache)
    assert second.open_session(session) == []
    again_name, again = second.current_field()
    assert again_name == name
    np.testing.assert_allclose(again, values, rtol=0, atol=1e-12)
    picture = second.image(size=(500, 400))
    differ = np.mean(np.any(np.abs(picture.astype(int) - image.astype(int)) > 8, axis=2))
    assert differ < 0.002, differ
    assert "feature distance" in wording.summary(second.state)
    second.show_current_mode()
    assert second.state.display.kind == "mode" and second.state.display.mode == 7
    second.close()


def test_messages_instead_of_dialogs(viewer, spot_path):
    statuses, errors = [], []
    viewer.events.status.connect(lambda text, _ms: statuses.append(text))
    viewer.events.error.connect(lambda title, text: errors.append((title, text)))
    with pytest.raises(ComputeError, match="Open a mesh first"):
        viewer.compute("laplacian", k=5)
    assert errors == [("modalviewer", "Open a mesh first.")]
    viewer.open_mesh(spot_path)
    assert any("2930 vertices" in s for s in statuses)  # the mesh's report
    viewer.cancel_computation()
    assert statuses[-1] == "No computation running."
    viewer.compute("laplacian", k=10)
    assert statuses[-1].startswith("Laplacian (cotan), 10 modes in ")
    assert "largest relative residual" in statuses[-1]
    assert viewer.clear_cache() > 0
    viewer.pick_vertex(5)
    assert viewer.picked == viewer.mesh.mesh_vertex(5)
    with pytest.raises(ValueError):
        viewer.show_distance(share=1.5)


def test_a_cached_spectrum_does_not_read_like_a_fresh_solve(viewer, spot_path, tmp_path):
    viewer.open_mesh(spot_path)
    viewer.compute("laplacian", k=10)
    solved = viewer.state.spectra[viewer.state.spectrum_key("laplacian")]
    assert not solved.from_cache
    again = Viewer(cache=mv.core.cache.SpectrumCache(tmp_path / "cache"))
    statuses = _statuses(again)
    again.open_mesh(spot_path)
    again.compute("laplacian", k=10)
    assert statuses[-1].startswith("Laplacian (cotan), 10 modes read from the cache in ")
    earlier = solved.parameters["seconds_total"]
    assert f"(solved earlier in {earlier:.1f} s)" in statuses[-1]
    again.close()


def test_asking_again_for_a_spectrum_in_memory_says_so(viewer, spot_path):
    """Found under Xvfb: Ctrl+R with the spectrum on screen did nothing and said
    nothing."""
    statuses = _statuses(viewer)
    viewer.open_mesh(spot_path)
    viewer.compute("laplacian", k=20)
    viewer.compute("laplacian", k=20)
    assert statuses[-1] == "Laplacian (cotan), 20 modes: already computed.", statuses[-3:]


def test_keep_the_largest_component(viewer, tmp_path):
    from modalviewer.core.primitives import icosphere, torus

    big, small = torus(24, 10), icosphere(1)
    big = mv.Mesh(3.0 * big.vertices, big.faces)
    vertices = np.vstack([big.vertices, small.vertices + (6.0, 0.0, 0.0)])
    faces = np.vstack([big.faces, small.faces + big.n_vertices])
    viewer.set_mesh(mv.Mesh(vertices, faces))
    assert viewer.mesh.n_components == 2
    repaired = viewer.repair_mesh("largest_component")
    assert viewer.mesh is repaired and repaired.n_vertices == len(vertices)  # the same numbers
    np.testing.assert_array_equal(repaired.unused, np.arange(big.n_vertices, len(vertices)))
    assert viewer.state.mesh.n_vertices == big.n_vertices  # solved on the torus alone


def test_a_shape_pair_without_a_window(viewer, tmp_path):
    """Mesh A as loaded, mesh B a rotated, scaled copy: the best match of a vertex on B
    is the vertex itself or its mirror image (the shapes' spectra do not see a rotation,
    and unit-area rescaling removes the scale)."""
    from modalviewer.core.primitives import icosphere

    a = icosphere(2)
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    bumpy = a.vertices * (1.0 + 0.2 * a.vertices[:, [0]] ** 2)  # not a round sphere
    viewer.set_mesh(mv.Mesh(bumpy, a.faces))
    b = mv.Mesh(bumpy @ rotation.T * 1.3, a.faces)
    viewer.state.set_display(distance_kind="hks")
    pair = viewer.pair(b, k=30)
    assert pair.ready() and pair.linked
    pair.pick("a", 5)
    d = pair.distance_on("b")
    assert d.shape == (b.n_vertices,)
    side, match, _ = pair.best_match()
    assert side == "b"
    # the vertex itself or one mirrored by the shape's symmetry: as far from the x axis
    assert abs(b.vertices[match, 2]) == pytest.approx(abs(b.vertices[5, 2]), abs=0.05)
    pair.linked = False
    assert not pair.linked


def test_a_field_of_your_own(viewer, spot_path):
    """Values a script gives are a display of the state: shown, named in the legend,
    exported, replaced, and dropped with the mesh."""
    viewer.open_mesh(spot_path)
    height = viewer.mesh.vertices[:, 1].copy()
    viewer.show_field("height", height)
    assert viewer.state.display.kind == "field"
    name, values = viewer.current_field()
    assert name == "height"
    np.testing.assert_array_equal(values, height)
    assert wording.legend(viewer.state).startswith("height: blue +, white 0, orange -")
    counts = _colours(viewer.image(size=(400, 300)))
    assert counts["blue"] > 500 and counts["orange"] > 500, counts
    viewer.state.add_field("height", height - height.min())  # replaced, redrawn
    assert viewer.current_field()[1].min() == 0.0
    assert "white to red" in wording.legend(viewer.state)
    with pytest.raises(ValueError, match="one value per vertex"):
        viewer.show_field("bad", height[:-1])
    with pytest.raises(ValueError, match="no field"):
        viewer.show_field("missing")
    viewer.open_mesh(spot_path)
    assert viewer.state.fields == {} and viewer.state.display.kind == "none"


def test_a_request_for_more_modes_than_the_mesh_has_says_how_many_came(viewer):
    """An icosphere of 42 vertices has 126 3D shells modes: asked for 500, the status
    line says 126 came and that they are all the mesh has (it said "500 modes in 0.1 s"
    while the plot showed 126)."""
    from modalviewer.core.primitives import icosphere

    viewer.set_mesh(icosphere(1))
    statuses = _statuses(viewer)
    spec = viewer.compute("shells", k=500)
    assert spec.k == 126
    done = [s for s in statuses if s.startswith("Discrete Shells (3D vibrations), 500 modes")]
    assert done and " (only 126: all the mesh has) in " in done[-1], statuses


def test_a_job_keeps_what_the_status_line_said_of_it(viewer, spot_path):
    """The starting message is kept on the job, once, for the Computations panel."""
    viewer.open_mesh(spot_path)
    statuses = _statuses(viewer)
    job = viewer.request_spectrum("laplacian", k=12)
    viewer.wait_for(job)
    started = [s for s in statuses if s.startswith("Computing Laplacian (cotan), 12 modes")]
    assert started and job.said == started[:1], (job.said, statuses)


def test_a_script_picks_without_computing_the_default_kinds_spectrum(viewer, spot_path):
    # pick_vertex then show_distance("hks") had started the 3D shells for the
    # default vibration distance as well
    viewer.open_mesh(spot_path)
    viewer.state.compute_settings.k = 12
    viewer.pick_vertex(123, show=False)
    assert viewer.picked == 123 and viewer.jobs.jobs == []
    viewer.show_distance("hks")
    operators = [job.spectrum_key.operator for job in viewer.jobs.jobs]
    assert operators == ["laplacian"]
    for job in list(viewer.jobs.jobs):
        viewer.wait_for(job)
    d = viewer.show_distance("hks")
    assert d.shape == (viewer.mesh.n_vertices,) and d[123] == 0.0


def test_a_size_given_to_one_picture_does_not_carry_over(viewer, spot_path, tmp_path):
    # after export_screenshot(size=(400, 300)), pictures without a size stayed 400 x 300
    from PIL import Image

    viewer.open_mesh(spot_path)
    small = viewer.export_screenshot(tmp_path / "small.png", size=(400, 300))
    assert Image.open(small).size == (400, 300)
    assert Image.open(viewer.export_screenshot(tmp_path / "default.png")).size == (1024, 768)
    assert viewer.image(size=(320, 200)).shape[:2] == (200, 320)
    assert viewer.image().shape[:2] == (768, 1024)
