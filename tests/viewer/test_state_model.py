"""The viewer's state model and jobs, without Qt or VTK."""

import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from modalviewer.core.cache import SpectrumCache
from modalviewer.core.primitives import icosphere
from modalviewer.viewer import ViewerModel, wording
from modalviewer.viewer.jobs import CANCELLED, DONE, FAILED, JobQueue

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture
def model(tmp_path):
    m = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    m.open_mesh(ASSETS / "spot.obj")
    return m


def test_importing_the_viewer_model_loads_no_qt_and_no_vtk():
    code = (
        "import sys, modalviewer, modalviewer.viewer, modalviewer.viewer.session;"
        "bad = [m for m in sys.modules if m.split('.')[0] in "
        "('PySide6', 'qtpy', 'vtk', 'vtkmodules', 'pyvista', 'pyvistaqt')];"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_each_wait_returns_its_own_spectrum(model):
    """Problem 1: a shells request made while a Laplacian request waited used to be
    returned to the Laplacian's caller (one shared wait, and the new job cancelled the
    old one)."""
    lap = model.request_spectrum("laplacian", k=37)
    shells = model.request_spectrum("shells", k=12)  # as a click on the surface does
    model.jobs.wait(lap)
    assert lap.status == DONE and lap.result[0].operator == "laplacian"
    assert lap.result[0].k == 37
    assert shells.status in ("queued", "running", DONE)  # not cancelled by anyone
    model.jobs.wait(shells)
    assert shells.status == DONE and shells.result[0].operator == "shells"
    assert model.state.spectrum("laplacian") is lap.result[0]
    assert model.state.spectrum("shells") is shells.result[0]


def test_identical_requests_join_one_job_and_others_queue(model):
    a = model.request_spectrum("modified_dirichlet", k=20)
    b = model.request_spectrum("modified_dirichlet", k=20)
    c = model.request_spectrum("modified_dirichlet", k=21)
    assert a is b and c is not a
    assert [j.status for j in model.jobs.jobs] == ["running", "queued"]
    model.jobs.cancel(c)
    assert c.status == CANCELLED and a.status == "running"
    model.jobs.wait(a)
    assert a.status == DONE


def test_a_failing_job_reports_its_own_error_and_the_queue_goes_on():
    queue = JobQueue()

    def boom(progress, cancel):
        raise RuntimeError("the matrix is singular")

    bad = queue.submit(boom, "bad", "bad")
    good = queue.submit(lambda p, c: 42, "good", "good")
    queue.wait(good, timeout=10)
    assert bad.status == FAILED and "singular" in bad.error
    assert good.status == DONE and good.result == 42


def test_an_expected_failure_keeps_no_traceback_and_a_fault_keeps_one(caplog):
    # a refusal whose message says it all (a non-manifold mesh for the shells) was
    # logged with a full traceback, which reads as a crash on a terminal
    import logging

    from modalviewer.core.mesh import MeshError
    from modalviewer.viewer import Viewer
    from modalviewer.viewer.process import ChildError

    queue = JobQueue()
    jobs = []
    for error in (MeshError("312 non-manifold edges"), ChildError("not converged"), KeyError(3)):

        def fail(progress, cancel, error=error):
            raise error

        jobs.append(queue.submit(fail, repr(error), "failing"))
    for job in jobs:
        queue.wait(job, timeout=10)
    refused, reported, fault = jobs
    assert refused.status == reported.status == fault.status == FAILED
    assert refused.details == "" and reported.details == ""
    assert "Traceback" in fault.details and "KeyError" in fault.details
    viewer = Viewer()
    try:
        with caplog.at_level(logging.WARNING, logger="modalviewer"):
            viewer._on_job_finished(refused)
            viewer._on_job_finished(fault)
        texts = [(r.levelname, r.getMessage()) for r in caplog.records]
        # the refusal once, in words, as the user is told it; the fault with its traceback
        assert texts[0] == ("WARNING", "The computation failed: 312 non-manifold edges")
        assert sum("312" in text for _, text in texts) == 1
        assert any(level == "ERROR" and "Traceback" in text for level, text in texts)
    finally:
        viewer.close()


def test_an_observer_that_raises_stops_neither_the_job_callbacks_nor_the_queue():
    """An observer of ``finished`` that raises (the window's handler did, for repair
    jobs) must not keep the job's own callbacks from running (a scripted wait on it
    never ended) nor the next job from starting."""
    queue = JobQueue()

    def broken_observer(job):
        raise TypeError("'Mesh' object is not subscriptable")

    queue.events.finished.connect(broken_observer)
    seen = []
    first = queue.submit(lambda p, c: "repaired mesh", "first", "first").then(seen.append)
    second = queue.submit(lambda p, c: 42, "second", "second")
    with pytest.raises(Exception, match="not subscriptable"):
        queue.wait(first, timeout=10)
    assert seen == [first] and first.status == DONE
    queue.events.finished.disconnect(broken_observer)
    queue.wait(second, timeout=10)
    assert second.status == DONE and second.result == 42


def test_cancel_a_running_job_ends_it_as_cancelled():
    queue = JobQueue()
    started = threading.Event()

    def slow(progress, cancel):
        started.set()
        while not cancel():
            time.sleep(0.01)
        return "never shown"

    job = queue.submit(slow, "slow", "slow")
    started.wait(5)
    queue.cancel(job)
    queue.wait(job, timeout=10)
    assert job.status == CANCELLED and job.result is None


def test_a_new_mesh_cancels_the_old_mesh_jobs_and_drops_their_result(model):
    job = model.request_spectrum("shells", k=30)
    model.set_mesh(icosphere(2))
    model.jobs.wait(job)
    assert job.status in (CANCELLED, DONE)
    assert model.state.spectrum("modified_dirichlet") is None


def test_a_finished_job_does_not_replace_a_display_changed_meanwhile(model):
    """Problem 2's cause: a result arriving later took over the picture."""
    model.jobs.wait(model.request_spectrum("laplacian", k=20, show=True))
    state = model.state
    assert state.display.kind == "mode" and state.display.operator == "laplacian"
    job = model.request_spectrum("modified_dirichlet", k=20, show=True)
    state.set_pick(100)
    state.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    model.jobs.wait(job)
    assert state.display.kind == "distance"  # the result did not take over
    assert state.spectrum("modified_dirichlet") is not None


def test_a_threshold_map_keeps_its_share_of_the_surface(model):
    """A threshold map chosen before the first pick marked what a fixed fraction of the
    largest distance happened to mark (95 % of a cow from its head, 67 % of a
    Cheburashka when the pick started the computation); a new pick, kind or spectrum
    kept the fraction, not the share.  Now the first map marks a tenth of the surface's
    area and later maps the share set last."""
    from modalviewer.core.laplacian import lumped_masses
    from modalviewer.viewer.state import DEFAULT_THRESHOLD_SHARE

    state = model.state
    areas = lumped_masses(state.mesh)

    def marked() -> float:  # share of the area, computed here
        d = state.derived.distance_map()
        return float(areas[d <= state.derived.threshold_value(d)].sum() / areas.sum())

    # threshold display chosen first; the pick starts the computation
    state.set_display(distance_kind="hks", distance_display="threshold")
    state.set_pick(100)
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_display(kind="distance")
    assert marked() == pytest.approx(DEFAULT_THRESHOLD_SHARE, abs=0.005)
    assert state.derived.marked_share() == pytest.approx(marked(), abs=1e-12)
    state.set_display(threshold=state.derived.threshold_for_share(0.25))
    assert marked() == pytest.approx(0.25, abs=0.005)
    for vertex in (2000, 2900, 5):
        state.set_pick(vertex)
        assert marked() == pytest.approx(0.25, abs=0.005)
    model.jobs.wait(model.request_spectrum("laplacian", k=40))  # another spectrum
    assert marked() == pytest.approx(0.25, abs=0.005)
    # another kind whose spectrum is computed after the switch
    state.set_display(threshold=state.derived.threshold_for_share(0.36))
    state.set_display(distance_kind="feature")
    assert state.derived.distance_map() is None
    model.jobs.wait(model.request_spectrum("modified_dirichlet", k=30))
    assert marked() == pytest.approx(0.36, abs=0.005)
    # by value: the fraction of the largest distance stays
    state.set_display(keep_share=False, threshold=0.5)
    state.set_pick(100)
    assert state.display.threshold == 0.5
    # a fraction asked for before its map is on screen is kept for it
    state.set_display(keep_share=True, kind="none")
    state.set_display(distance_kind="hks", threshold=0.3)
    state.set_display(kind="distance")
    assert state.display.threshold == 0.3
    share = marked()
    state.set_pick(200)  # and the share it marks is the one kept
    assert marked() == pytest.approx(share, abs=0.005)


def test_legend_and_summary_follow_the_threshold(model):
    """Problem 5: the status kept the first threshold's numbers while the slider moved."""
    state = model.state
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_pick(500)
    state.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    from modalviewer.core.laplacian import lumped_masses

    areas = lumped_masses(state.mesh)
    for share in (0.05, 0.2, 0.6):
        state.set_display(threshold=state.derived.threshold_for_share(share))
        d = state.derived.distance_map()
        marked = float(areas[d <= state.derived.threshold_value()].sum() / areas.sum())
        assert marked == pytest.approx(share, abs=0.01)
        assert f"{100 * marked:.1f} % of the surface" in wording.summary(state)
        assert f"{100 * marked:.1f} % of the surface" in wording.legend(state)
        field = state.derived.field()
        assert field.colormap == "threshold"
        np.testing.assert_array_equal(field.values, d)
        assert field.share_similar == pytest.approx(marked, abs=1e-12)


def test_field_is_derived_from_the_state(model):
    state = model.state
    assert state.derived.field().colormap == "plain"
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=True))
    assert state.display.mode == 1  # the first non-zero mode: mode 0 is constant
    field = state.derived.field()
    spec = state.spectrum("laplacian")
    np.testing.assert_allclose(field.values, spec.mode(1), rtol=0, atol=0)
    assert field.colormap == "diverging" and field.isolines == state.style.isolines
    assert "Laplacian (cotan), mode 1" in wording.legend(state)
    state.set_display(kind="curvature")
    curvature = state.derived.field()
    # from 0 on a linear range; a spread range runs from the smallest value
    low = curvature.values.min() if curvature.color_range == "spread" else 0.0
    assert curvature.clim[0] == low


def test_display_validation_and_clipping(model):
    state = model.state
    with pytest.raises(ValueError, match="no spectrum"):
        state.set_display(kind="mode", operator="shells")
    with pytest.raises(ValueError, match="distance kind"):
        state.set_display(distance_kind="nonsense")
    with pytest.raises(ValueError, match="does not exist"):
        state.set_pick(10**9)
    model.jobs.wait(model.request_spectrum("laplacian", k=12))
    state.show_mode(99, "laplacian")
    assert state.display.mode == 11


def test_events_fire_once_per_change(model):
    state = model.state
    seen = []
    state.events.display.connect(lambda: seen.append("display"))
    state.events.style.connect(lambda: seen.append("style"))
    state.style.isolines = 5
    state.style.isolines = 5  # no change, no event
    state.set_display(distance_display="threshold")
    state.set_display(distance_display="threshold")
    assert seen == ["style", "display"]


def test_the_style_fields_are_validated_when_set_and_say_so_once():
    from modalviewer.viewer import Viewer
    from modalviewer.viewer.state import ViewerState

    viewer = Viewer()
    assert isinstance(viewer, ViewerModel) and isinstance(viewer.state, ViewerState)
    style, seen = viewer.state.style, []
    viewer.state.events.style.connect(lambda: seen.append("style"))
    style.isolines = 99
    assert style.isolines == 60 and seen == ["style"]  # clipped to 0..60
    style.isolines = -3
    assert style.isolines == 0 and len(seen) == 2
    style.shell_coloring = "auto"  # the former name of the deformed shape
    assert style.shell_coloring == "deformed" and len(seen) == 2  # unchanged: no event
    with pytest.raises(ValueError, match="colouring must be one of"):
        style.shell_coloring = "wavy"
    with pytest.raises(ValueError, match="render style must be one of"):
        style.render = "cartoon"
    assert (style.shell_coloring, style.render, len(seen)) == ("deformed", "paper", 2)
    style.ghost = 0
    assert style.ghost is False and len(seen) == 3
    viewer.state.set_color_range("limits", (0.0, 2.0))  # range and limits: one event
    assert (style.color_range, style.color_limits, len(seen)) == ("limits", (0.0, 2.0), 4)
    viewer.close()


def test_animation_settings_camera_and_up_axis_are_evented_fields(model):
    state, seen = model.state, []
    for name in ("animation", "compute_settings", "camera", "up_axis"):
        getattr(state.events, name).connect(lambda *_, name=name: seen.append(name))
    state.animation.amplitude = 250
    state.animation.amplitude = 100  # the same after clipping: no event
    state.animation.speed = 0
    assert (state.animation.amplitude, state.animation.speed) == (100, 1)
    state.animation.playing = True  # only a mode plays: stays still, says nothing
    assert state.animation.playing is False and seen == ["animation", "animation"]
    state.compute_settings.k = "12"
    state.compute_settings.k = 12
    assert state.compute_settings.k == 12 and seen[2:] == ["compute_settings"]
    with pytest.raises(ValueError, match="at least 1"):
        state.compute_settings.k = 0
    with pytest.raises(ValueError, match="unknown operator"):
        state.compute_settings.operator = "nonsense"
    assert (state.compute_settings.k, state.compute_settings.operator) == (12, "modified_dirichlet")
    state.up_axis = "+Z"
    state.up_axis = "+z"
    with pytest.raises(ValueError, match="up axis"):
        state.up_axis = "up"
    assert state.up_axis == "+z" and seen[3:] == ["up_axis"]
    camera = {"position": [0, 0, 5], "focal_point": [0, 0, 0], "view_up": [0, 1, 0]}
    state.camera = camera
    state.camera = dict(camera)  # set again: applied again
    assert seen[4:] == ["camera", "camera"]
    model.jobs.wait(model.request_spectrum("laplacian", k=8))
    state.show_mode(1, "laplacian")
    state.animation.playing = True
    assert state.animation.playing and seen[-1] == "animation"
    state.set_display(kind="curvature")  # a picture that does not vibrate stops it
    assert not state.animation.playing and seen[-1] == "animation"
    del seen[:]
    state.set_mesh(icosphere(1))  # the mesh event says it all
    assert state.camera is None and state.up_axis is None and seen == []


def test_a_new_spectrum_of_an_operator_replaces_its_other_keys(model):
    """Every k used to stay in memory (3.0 GB after 18 requests at 130k) and in saved
    sessions, with one of them shown."""
    first = model.request_spectrum("laplacian", k=12)
    model.jobs.wait(first)
    shells = model.request_spectrum("shells", k=8)
    model.jobs.wait(shells)
    second = model.request_spectrum("laplacian", k=15)
    model.jobs.wait(second)
    keys = sorted((key.operator, key.k) for key in model.state.spectra)
    assert keys == [("laplacian", 15), ("shells", 8)]
    assert model.state.spectrum("laplacian").k == 15


def test_a_child_computation_reports_its_hand_over_below_one(tmp_path):
    """The progress bar read "done 100 %" for 1-2 s at 130k while the spectrum was
    still written, read back and prepared."""
    from modalviewer.viewer.process import compute_in_process

    mesh = icosphere(2)
    stages = []
    spec = compute_in_process(
        mesh, "laplacian", 10, 1.0, 1.0, tmp_path / "out.npz",
        lambda stage, fraction: stages.append((stage, fraction)), lambda: False,
    )  # fmt: skip
    assert spec.k == 10
    names = [s for s, _ in stages]
    assert "done" not in names
    assert names[-2:] == ["writing the result", "reading the result"]
    assert all(f < 1.0 for _, f in stages)


def test_a_coarse_to_fine_spectrum_is_marked_as_approximate(model):
    """Found under Xvfb: a coarse-to-fine result replaced the exact spectrum and was
    listed and drawn as a plain Laplacian spectrum (lambda_1 9.388 against 9.377)."""
    state = model.state
    state.compute_settings.coarse = True
    job = model.request_spectrum("laplacian", k=12, show=True)
    model.jobs.wait(job)
    assert state.is_coarse("laplacian") and wording.display_mark(state) == " (coarse-to-fine)"
    assert state.derived.field().title.endswith("(coarse-to-fine)")
    assert "(coarse-to-fine: approximate)" in wording.legend(state)
    state.compute_settings.coarse = False
    exact = model.request_spectrum("laplacian", k=12, show=True)
    model.jobs.wait(exact)
    assert not state.is_coarse("laplacian") and wording.display_mark(state) == ""
    assert "coarse" not in wording.legend(state)


def test_a_new_number_of_modes_keeps_the_mode_on_screen(model):
    """Found under Xvfb: computing 20 modes while mode 7 of 12 was shown went back to
    the first non-zero mode."""
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=True))
    model.state.show_mode(7)
    model.jobs.wait(model.request_spectrum("laplacian", k=20, show=True))
    assert model.state.spectrum("laplacian").k == 20
    assert model.state.display.mode == 7
    field = model.state.derived.field()
    np.testing.assert_array_equal(field.values, model.state.spectrum("laplacian").mode(7))
    model.jobs.wait(model.request_spectrum("laplacian", k=5, show=True))
    assert model.state.display.mode == 4  # fewer modes now: the last one


def test_asking_again_for_the_spectrum_on_screen_keeps_the_mode(model):
    """Found under Xvfb: Ctrl+R on the Laplacian at mode 5 went back to mode 3 (its
    first non-zero mode), Compute on E_D^N at mode 9 to mode 0."""
    job = model.request_spectrum("laplacian", k=12, show=True)
    model.jobs.wait(job)
    model.state.show_mode(7)
    again = model.request_spectrum("laplacian", k=12, show=True)
    assert again.done and model.state.display.mode == 7
    model.state.set_pick(100)
    model.state.set_display(kind="distance", distance_kind="hks")
    model.request_spectrum("laplacian", k=12, show=True)
    assert model.state.display.kind == "distance"
    # another operator's spectrum, asked for from the picture of this one, is shown
    other = model.request_spectrum("modified_dirichlet", k=12, show=True)
    model.jobs.wait(other)
    model.state.show_mode(5, "laplacian")
    model.request_spectrum("modified_dirichlet", k=12, show=True)
    assert model.state.display.operator == "modified_dirichlet"


def test_the_status_line_says_what_is_computing_before_any_spectrum(model):
    """Found under Xvfb: while the first spectrum (the vibration distance's, started by a
    click) was computed the status line still said "compute a spectrum (Ctrl+R) or click
    the surface"."""
    state = model.state
    assert "compute a spectrum (Ctrl+R)" in wording.summary(state)
    state.set_pick(100)
    job = model.request_spectrum("shells", k=12)
    assert "computing Discrete Shells" in wording.summary(state)
    assert "the map of vertex 100 follows" in wording.summary(state)
    assert "Ctrl+R" not in wording.summary(state)
    model.jobs.wait(job)
    assert not state.computing and "computing" not in wording.summary(state)
    cancelled = model.request_spectrum("laplacian", k=12)
    model.jobs.cancel(cancelled)
    model.jobs.wait(cancelled)
    assert not state.computing


def test_a_refusal_says_what_would_fit(monkeypatch):
    """A request too large for the machine names the most modes that fit (checked
    against the estimate itself) and whether Coarse-to-fine fits."""
    from modalviewer.core import memory
    from modalviewer.core.operators import operator_info
    from modalviewer.core.primitives import icosphere
    from modalviewer.viewer import model as model_module

    m = model_module.ViewerModel()
    m.set_mesh(icosphere(4))
    key = m.state.compute_settings.key("shells", 300)
    n, shells = m.state.mesh.n_vertices, operator_info("shells")

    # memory for about 150 of the 300 modes asked for
    needed = shells.predicted_peak_mb(n, 150) * memory.MB
    available = int(needed / memory.MEMORY_SHARE)
    # the solver's choices (out of core, float32 basis) stay those of this machine
    monkeypatch.setenv("MODALVIEWER_MEMORY_LIMIT_MB", str(memory.memory_limit_mb()))
    monkeypatch.setattr(memory, "physical_memory_mb", lambda: available / 2**20)
    message = m.refusal(key)
    k = memory.largest_k_that_fits(shells, 300, n, available)
    assert 1 <= k < 300 and f"at most {k} modes fit" in message.lower()
    limit = memory.MEMORY_SHARE * available
    assert shells.predicted_peak_mb(n, k) * memory.MB <= limit
    assert shells.predicted_peak_mb(n, k + 1) * memory.MB > limit
    assert "Coarse-to-fine" in message
    # it names the limit it applies, not only the machine's memory (above which a
    # refused request's need can lie)
    assert (
        f"more than the {limit / 2**30:.1f} GiB a computation may take (three quarters of "
        f"this machine's {available / 2**30:.1f} GiB)" in message
    ), message
    monkeypatch.setattr(memory, "physical_memory_mb", lambda: 1024 / 2**20)
    assert "Not even one mode fits" in m.refusal(key)


def test_a_refusal_offers_no_option_that_cannot_give_the_modes_asked_for(monkeypatch):
    """More modes than the decimated copy has unknowns: Coarse-to-fine is not offered (a
    refusal of a million shells modes on a 46k mesh
    said "1000000 modes with Coarse-to-fine (a decimated copy) fit")."""
    from modalviewer.coarsen import COARSE_FRACTION
    from modalviewer.core import memory
    from modalviewer.core.operators import operator_info
    from modalviewer.core.primitives import icosphere
    from modalviewer.viewer import model as model_module

    m = model_module.ViewerModel()
    m.set_mesh(icosphere(4))  # 2562 vertices; the copy 512, 1536 shells unknowns
    n, shells = m.state.mesh.n_vertices, operator_info("shells")
    copy = round(COARSE_FRACTION * n)
    too_many = 3 * copy + 1
    # enough memory for the copy's solve and for 300 modes, not for the request
    available = int(
        max(
            shells.predicted_peak_mb(copy, too_many) * memory.MB,
            shells.predicted_peak_mb(n, 300) * memory.MB,
        )
        / memory.MEMORY_SHARE
    )
    assert shells.predicted_peak_mb(n, too_many) * memory.MB > memory.MEMORY_SHARE * available
    monkeypatch.setenv("MODALVIEWER_MEMORY_LIMIT_MB", str(memory.memory_limit_mb()))
    monkeypatch.setattr(memory, "physical_memory_mb", lambda: available / 2**20)
    message = m.refusal(m.state.compute_settings.key("shells", too_many))
    assert "Coarse-to-fine" not in message, message
    assert "modes fit" in message
    fewer = too_many - 1  # as many as the copy has: offered
    assert "Coarse-to-fine" in memory.what_fits(shells, fewer, n, available, copy, "Coarse-to-fine")


def test_a_share_marks_its_boundary_vertex_whatever_the_rounding(model):
    """The fraction of the largest distance that marks a share is compared with
    ``fraction * max(d)``; for these numbers ``(v / m) * m < v`` in floating point, which
    left the vertex at the share's boundary out (9.98 % marked for 10 % asked)."""
    from modalviewer.core.laplacian import lumped_masses

    state = model.state
    areas = lumped_masses(state.mesh)
    n = areas.shape[0]
    v, m = 0.028319671145462966, 1.1242832764995638
    assert (v / m) * m < v
    j = n // 10
    d = np.empty(n)
    d[:j] = np.linspace(0.0, 0.5 * v, j)
    d[j] = v
    d[j + 1 :] = np.linspace(2 * v, m, n - j - 1)
    share = float(np.cumsum(areas)[j] / areas.sum())
    fraction = state.derived.threshold_for_share(share, d)
    marked = float(areas[d <= fraction * d.max()].sum() / areas.sum())
    assert marked >= share - 1e-12
    assert marked == pytest.approx(share, abs=1e-12)  # and not the next vertex too


def test_distances_equal_up_to_round_off_are_marked_all_or_none(model):
    """A share whose threshold falls among distances equal to 1e-9 (where the signatures
    all but vanish at every scale: 6.9 % of the cow's area) marks all of them; round-off
    decided each vertex before (speckles)."""
    from modalviewer.core.laplacian import lumped_masses

    state = model.state
    areas = lumped_masses(state.mesh)
    n = areas.shape[0]
    rng = np.random.default_rng(3)
    d = np.linspace(0.0, 1.0, n)
    flat = rng.random(n) < 0.2  # a fifth of the vertices at one value, with round-off
    d[flat] = 0.3 + 1e-9 * rng.standard_normal(int(flat.sum()))  # 1e-9 of the largest
    below = float(areas[d < 0.3 - 1e-6].sum() / areas.sum())
    within = float(areas[flat].sum() / areas.sum())
    fraction = state.derived.threshold_for_share(below + 0.5 * within, d)
    marked = d <= fraction * d.max()
    assert marked[flat].all()
    assert float(areas[marked].sum() / areas.sum()) == pytest.approx(below + within, abs=1e-3)


def test_a_cancelled_child_leaves_no_factor_folder(tmp_path, monkeypatch):
    """A solve killed by Cancel cannot remove its out-of-core factor file; the viewer
    removes the folders of ended processes once its child has ended."""
    from modalviewer.core.eigen import Cancelled
    from modalviewer.core.factor import FOLDER_PREFIX
    from modalviewer.viewer import process

    factors = tmp_path / "factors"
    factors.mkdir()
    (tmp_path / "fake_solver.py").write_text(
        "import json, os, sys, time\n"
        f"folder = os.path.join({str(factors)!r}, '{FOLDER_PREFIX}' + str(os.getpid()) + '-x')\n"
        "os.mkdir(folder)\n"
        "open(os.path.join(folder, 'mkl_pardiso_lnz_0_0.bin'), 'wb').write(b'0' * 1000)\n"
        "print(json.dumps({'stage': 'solving', 'fraction': 0.5}), flush=True)\n"
        "time.sleep(60)\n"
    )
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    monkeypatch.setenv("MODALVIEWER_FACTOR_DIR", str(factors))
    stages = []

    def cancel() -> bool:
        return bool(stages)  # once the child is solving, with its factor file written

    with pytest.raises(Cancelled):
        process._run_child(["fake_solver"], lambda s, f: s != "starting" and stages.append(s),
                           cancel, "computation")  # fmt: skip
    assert stages == ["solving"]
    assert not list(factors.iterdir())
