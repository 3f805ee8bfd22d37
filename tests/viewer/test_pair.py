"""The shape pair's state (viewer/pair.py): a pick on one mesh, distances on the other,
spectra through the job queue; no Qt, no VTK."""

import re
from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.cache import SpectrumCache
from modalviewer.core.laplacian import lumped_masses
from modalviewer.viewer import ViewerModel
from modalviewer.viewer.jobs import JobQueue, ManualDispatcher
from modalviewer.viewer.pair import PairState

ASSETS = Path(__file__).resolve().parents[2] / "assets"
K = 20


def _moved(mesh, scale=1.0, seed=3):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return mv.Mesh(scale * mesh.vertices @ q.T + [0.5, -1.0, 2.0], mesh.faces)


@pytest.fixture(scope="module")
def spot():
    return mv.load_mesh(ASSETS / "spot.obj")


def _pair(tmp_path, a, b, **kw):
    jobs = JobQueue(ManualDispatcher())
    pair = PairState(jobs, SpectrumCache(tmp_path / "cache"), a, b, "spot.obj", "moved.obj", **kw)
    return pair


def _wait(pair):
    for job in pair.request():
        pair.jobs.wait(job, timeout=120)
    assert pair.ready(), pair.failure()


def test_rigid_motion_pick_on_a_matches_the_same_vertex_on_b(tmp_path, spot):
    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    displays = []
    pair.events.display.connect(lambda: displays.append(1))
    assert pair.view("b").values is None and "click A or B" in pair.view("b").legend
    _wait(pair)
    assert displays  # the window redraws when the spectra arrive
    for v in (0, 700, 2900):
        pair.pick("a", v)
        d = pair.distance_on("b")
        assert d.shape == (spot.n_vertices,) and pair.distance_on("a") is None
        # the distance to the moved copy of the picked vertex is zero (round-off)
        assert d[v] <= 1e-8 * d.max()
        assert pair.best_match()[:2] == ("b", v) and pair.back_match() == v
        view = pair.view("b")
        assert view.colormap == "sequential" and view.marker == v
        assert f"best match: vertex {v} " in view.legend
        assert "\nmutual" in pair.view("a").legend and pair.view("a").back_marker is None
    # the same numbers as the library's function
    np.testing.assert_allclose(
        pair.distance_on("b"),
        mv.cross_distance(pair.spectrum("a"), 2900, pair.spectrum("b")),
        rtol=0,
        atol=1e-12 * pair.distance_on("b").max(),
    )


def test_a_pick_on_b_works_the_other_way(tmp_path, spot):
    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    _wait(pair)
    pair.pick("b", 1234)
    d = pair.distance_on("a")
    expected = mv.cross_distance(pair.spectrum("b"), 1234, pair.spectrum("a"))
    np.testing.assert_allclose(d, expected, rtol=0, atol=1e-12 * expected.max())
    assert pair.best_match()[:2] == ("a", 1234)
    assert pair.view("a").marker == 1234 and pair.view("b").marker == 1234


def test_threshold_marks_the_asked_share_of_b_by_area(tmp_path, spot):
    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    _wait(pair)
    pair.pick("a", 700)
    pair.set_display("threshold", share=0.084)
    view = pair.view("b")
    d = pair.distance_on("b")
    masses = lumped_masses(pair.mesh("b"))
    share_at = masses[d <= view.threshold].sum() / masses.sum()
    below = masses[d < view.threshold].sum() / masses.sum()
    # the smallest level whose sub-level set covers 8.4 % of the area
    assert below < 0.084 <= share_at < 0.084 + 0.01
    m = re.search(r"blue: heat kernel distance < ([0-9.e-]+), ([0-9.]+) % of B", view.legend)
    assert m, view.legend
    assert float(m.group(1)) == pytest.approx(view.threshold, rel=1e-2)
    assert float(m.group(2)) == pytest.approx(100 * share_at, abs=0.05)
    assert view.colormap == "threshold" and view.colorbar_labels[1] == "the rest"
    pair.set_display("threshold", share=0.0)  # only the best match itself
    assert pair.view("b").threshold == pytest.approx(d.min())
    with pytest.raises(ValueError, match="display must be"):
        pair.set_display("blue")


def test_rescale_makes_a_larger_copy_comparable(tmp_path, spot):
    big = _moved(spot, scale=1.7)
    pair = _pair(tmp_path, spot, big, k=K, rescale=False)
    _wait(pair)
    pair.pick("a", 700)
    d = pair.distance_on("b")
    assert "areas differ" in pair.note and "areas differ" in pair.view("b").legend
    assert d[700] > 0.3 * d.max()  # unscaled: the copy is far everywhere
    pair.rescale = True
    assert pair.distance_on("b") is None  # unit-area spectra are not in yet
    _wait(pair)
    d = pair.distance_on("b")
    assert pair.note == "" and d[700] <= 1e-6 * d.max() and pair.best_match()[1] == 700
    assert pair.spectrum("a").mass.sum() == pytest.approx(1.0, rel=1e-9)


def test_spectra_of_a_come_from_the_main_state_and_the_disk_cache(tmp_path, spot, monkeypatch):
    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.set_mesh(spot, ASSETS / "spot.obj")
    model.state.compute_settings.rescale = True
    model.jobs.wait(model.request_spectrum("laplacian", K), timeout=120)
    pair = PairState(
        model.jobs, model.cache, spot, _moved(spot), state_a=model.state, k=K, rescale=True
    )
    jobs = pair.request()
    assert [j.owner[2] for j in jobs] == ["b"]  # A's spectrum is the main window's
    assert pair.spectrum("a") is model.state.spectrum("laplacian")
    for job in jobs:
        model.jobs.wait(job, timeout=120)

    # a second pair on the same meshes reads both from the disk cache, computing nothing
    def no_compute(*args, **kwargs):
        raise AssertionError("computed instead of read from the cache")

    monkeypatch.setattr("modalviewer.spectra.compute_spectrum", no_compute)
    again = PairState(model.jobs, model.cache, spot, _moved(spot), k=K)
    jobs = again.request()
    for job in jobs:
        model.jobs.wait(job, timeout=120)
    assert len(jobs) == 2 and again.ready(), again.failure()
    np.testing.assert_array_equal(again.spectrum("b").eigenvalues, pair.spectrum("b").eigenvalues)


def test_bad_input_gets_clear_errors(tmp_path, spot):
    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    in_words = r"B: vertex 5000 is not in the file \(it has 2930 vertices, numbered 0 to 2929\)"
    with pytest.raises(ValueError, match=in_words):
        pair.pick("b", 5000)
    with pytest.raises(ValueError, match="integer"):
        pair.pick("a", 1.5)
    with pytest.raises(ValueError, match="side must be"):
        pair.pick("c", 1)
    with pytest.raises(ValueError, match="distance kind"):
        pair.kind = "curvature"
    with pytest.raises(ValueError, match="at least 1"):
        pair.k = 0
    with pytest.raises(ValueError, match="between 0 and 1"):
        pair.share = float("nan")
    seen = []
    pair.events.display.connect(lambda: seen.append("display"))
    pair.events.linked.connect(seen.append)
    pair.share = 2.0  # clipped to the whole area
    pair.share = 1.0  # no change: no event
    pair.kind, pair.k, pair.linked = "wks", "12", False
    assert (pair.share, pair.k, seen) == (1.0, 12, ["display", "display", "display", False])


def test_replacing_a_mesh_cancels_its_jobs_and_drops_the_pick(tmp_path, spot):
    pair = _pair(tmp_path, spot, _moved(spot), k=K, kind="feature")
    jobs = pair.request()
    assert len(jobs) == 2
    pair.pick("a", 3)
    pair.set_mesh("b", _moved(spot, seed=9), "other.obj")
    for job in jobs:
        pair.jobs.wait(job, timeout=120)
    assert jobs[1].status == "cancelled" and pair.picked is None
    assert pair.name("b") == "other.obj" and pair.spectrum("b") is None
    pair.pick("a", 3)
    assert "computing the Modified Dirichlet energy E_D^N spectrum of B" in pair.view("b").legend


def test_a_cancel_is_not_reported_as_a_failure_and_a_failure_is(tmp_path, spot, monkeypatch):
    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    messages = []
    pair.events.message.connect(messages.append)
    jobs = pair.request()
    pair.cancel()
    for job in jobs:
        pair.jobs.wait(job, timeout=120)
    pair.pick("a", 5)
    assert messages == [] and "cancelled; pick again to compute" in pair.view("b").legend

    def broken(*args, **kwargs):
        raise ValueError("the factorisation broke")

    monkeypatch.setattr("modalviewer.spectra.compute_spectrum", broken)
    for job in pair.request():  # asked again: computed again (and failing now)
        pair.jobs.wait(job, timeout=120)
    assert len(messages) == 2 and "could not be computed: the factorisation broke" in messages[0]
    assert "failed: the factorisation broke" in pair.view("b").legend


def _with_unused(mesh, start, middle, end, at=1000):
    """``mesh`` with vertices no face uses: ``start`` before its first vertex, ``middle``
    before vertex ``at`` and ``end`` after its last (input vertex v is then v + start
    below ``at``, v + start + middle from there)."""
    far = np.full((1, 3), 9.0)
    v = mesh.vertices
    vertices = np.vstack([far.repeat(start, 0), v[:at], far.repeat(middle, 0), v[at:]])
    vertices = np.vstack([vertices, far.repeat(end, 0)])
    faces = np.where(mesh.faces < at, mesh.faces + start, mesh.faces + start + middle)
    return mv.as_mesh((vertices, faces))


def test_the_pair_speaks_the_input_numbering_on_meshes_with_unused_vertices(tmp_path, spot):
    # A: spot with 3 unused vertices at the start, 4 before vertex 1000, 2 at the end;
    # B: a moved copy with 5 at the start and 1 at the end.  Spot's vertex 700 is input
    # vertex 703 of A and 705 of B; its vertex 2000 is 2007 of A and 2005 of B
    a = _with_unused(spot, 3, 4, 2)
    b = _with_unused(_moved(spot), 5, 0, 1)
    pair = _pair(tmp_path, a, b, k=K)
    assert pair.mesh("a").n_vertices == a.n_vertices == spot.n_vertices + 9
    _wait(pair)
    pair.pick("a", 703)
    assert pair.picked == ("a", 703)
    d = pair.distance_on("b")
    assert d.shape == (b.n_vertices,)
    assert np.isnan(d[b.unused]).all() and np.isfinite(np.delete(d, b.unused)).all()
    assert d[705] <= 1e-8 * np.nanmax(d)
    side, w, dist = pair.best_match()
    assert (side, w) == ("b", 705) and dist <= 1e-8 * np.nanmax(d)
    assert pair.back_match() == 703
    assert "picked vertex 703\n" in pair.view("a").legend
    assert "best match: vertex 705 " in pair.view("b").legend
    pair.pick("b", 2005)
    assert pair.best_match()[:2] == ("a", 2007) and pair.back_match() == 2005
    assert pair.distance_on("a").shape == (a.n_vertices,)
    m = pair.mutual_best_matches([703, 2007])
    np.testing.assert_array_equal(m.vertices_a, [703, 2007])
    np.testing.assert_array_equal(m.matches_b, [705, 2005])
    np.testing.assert_array_equal(m.back_matches_a, [703, 2007])
    assert m.mutual.all()
    # the threshold covers the share asked for of A's area (its unused vertices have none)
    pair.set_display("threshold", share=0.1)
    value, covered = pair.threshold("a")
    masses = lumped_masses(a.solver_mesh)
    d = pair.distance_on("a")[a.solver_mesh.file_vertices]
    assert 0.1 <= covered <= 0.1 + masses.max() / masses.sum() + 1e-12
    assert covered == pytest.approx(masses[d <= value].sum() / masses.sum(), abs=1e-12)
    for side, vertex in (("a", 0), ("a", 1005), ("a", 2938), ("b", 2935)):
        with pytest.raises(ValueError, match=f"{side.upper()}: .*{vertex}"):
            pair.pick(side, vertex)  # no face uses it
    with pytest.raises(ValueError, match="does not exist|not in"):
        pair.pick("a", a.n_vertices)


def test_the_wave_kernel_distance_between_shapes_is_its_own(tmp_path, spot):
    """The heat and wave kernel kinds share the Laplacian's spectrum; switching between
    them gives each its own tables (a cache keyed by the spectra alone served the heat
    kernel's for both)."""
    moved = _moved(spot)
    pair = _pair(tmp_path, spot, moved, k=K, kind="hks")
    _wait(pair)
    pair.pick("a", 700)
    heat = pair.distance_on("b").copy()
    pair.kind = "wks"
    _wait(pair)
    wave = pair.distance_on("b")
    spec_a, spec_b = pair.spectrum("a"), pair.spectrum("b")
    expected = mv.CrossTables(spec_a, spec_b, kind="wks").a_to_b(700)
    np.testing.assert_allclose(wave, expected, rtol=1e-10, atol=1e-12 * expected.max())
    assert not np.allclose(wave / wave.max(), heat / heat.max())
    assert wave[700] <= 1e-8 * wave.max()


def test_maps_are_drawn_from_the_first_modes_while_the_rest_arrive(tmp_path, spot):
    """B's modes arrive as they converge: the pair's maps use them at once and say so,
    and are redrawn from the whole spectra when it is in."""
    import threading

    from modalviewer import spectra as spectra_module

    go, paused = threading.Event(), threading.Event()
    solve = spectra_module.compute_spectrum

    solves = []

    def compute_spectrum(mesh, *args, on_modes=None, **kwargs):
        solves.append(mesh)
        second = len(solves) == 2  # A's spectrum is solved first, then B's

        def hand_over(spec):
            on_modes(spec)
            if second and spec.k >= 10 and not spec.is_complete:
                paused.set()
                go.wait(120)

        return solve(mesh, *args, on_modes=hand_over, **kwargs)

    moved = _moved(spot)
    pair = _pair(tmp_path, spot, moved, k=60)
    original = spectra_module.compute_spectrum
    spectra_module.compute_spectrum = compute_spectrum
    try:
        jobs = pair.request()
        pair.pick("a", 700)
        pair.jobs.wait(jobs[0], timeout=120)  # A's whole spectrum
        assert paused.wait(120)  # B's solve waits after its first modes
        pair.jobs.dispatch.process(timeout=0.5)
        first = pair.spectrum("b")
        assert first is not None and 10 <= first.k < 60 and not first.is_complete
        view = pair.view("b")
        assert view.values is not None
        assert f"from the first {first.k} of 60 modes of B" in view.legend
        go.set()
        pair.jobs.wait(jobs[1], timeout=120)
    finally:
        go.set()
        spectra_module.compute_spectrum = original
    assert pair.spectrum("b").is_complete and "modes of B" not in pair.view("b").legend
    assert pair.best_match()[:2] == ("b", 700)


def test_the_pair_estimates_the_time_of_its_missing_spectra(tmp_path, spot):
    from modalviewer.core.cache import SolveRecord

    pair = _pair(tmp_path, spot, _moved(spot), k=K)
    key = pair.key()
    meshes = [pair.compute_mesh(side, key) for side in ("a", "b")]
    records = [
        SolveRecord(key.operator, mesh.hash, mesh.n_vertices, K, seconds)
        for mesh, seconds in zip(meshes, (3.0, 5.0), strict=True)
    ]
    pair.cache.solves = lambda: records  # this machine's recorded solves of both
    assert pair.estimated_seconds() == pytest.approx(8.0)
    _wait(pair)
    assert pair.estimated_seconds() is None  # nothing is missing


def test_while_a_sides_first_modes_are_in_the_legend_says_both_sides_are_computing(tmp_path, spot):
    """A's first modes arrive (its job still running) and B has none: both are being
    computed, and the legend names A and B, not B alone."""
    import dataclasses

    pair = _pair(tmp_path, spot, _moved(spot), k=K, kind="feature")
    key = pair.key()
    whole = mv.compute_spectrum(spot, key.operator, k=K)
    first = dataclasses.replace(whole, parameters={**whole.parameters, "modes_requested": 40})
    assert not first.is_complete
    pair._on_job(("a", spot.hash, key), None, first)  # as the job hands its first modes over
    assert pair.spectrum("a") is first and pair.spectrum("b") is None
    pair.pick("a", 3)
    label = "Modified Dirichlet energy E_D^N"
    assert f"computing the {label} spectrum of A and B" in pair.view("b").legend


def test_the_legend_of_a_continuous_map_on_the_other_mesh_names_its_range(tmp_path, spot):
    """On B, the distance from A's vertex is nowhere 0 (B is a noisy copy): the legend
    names the range the colours span, from the best match's distance, not from 0."""
    noise = 0.004 * np.random.default_rng(5).normal(size=spot.vertices.shape)
    pair = _pair(tmp_path, spot, mv.Mesh(_moved(spot).vertices + noise, spot.faces), k=K)
    _wait(pair)
    pair.pick("a", 700)
    view = pair.view("b")
    lo, hi = float(np.nanmin(view.values)), float(np.nanmax(view.values))
    assert lo > 1e-3 * hi  # no vertex of B has distance 0
    assert f"white {lo:.3g} to red {hi:.3g}" in view.legend, view.legend
