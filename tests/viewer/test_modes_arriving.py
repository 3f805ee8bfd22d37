"""The viewer shows a spectrum's modes as they converge: the state holds the first modes
while the rest are computed, legends say what a map is made of, nothing the user chose is
reset when the rest arrive, and a cancelled computation leaves nothing in the cache."""

import threading
from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer import spectra as spectra_module
from modalviewer.core.cache import SpectrumCache
from modalviewer.viewer import wording
from modalviewer.viewer.jobs import CANCELLED, DONE
from modalviewer.viewer.process import compute_in_process

SPOT = Path(__file__).resolve().parents[2] / "assets" / "spot.obj"


@pytest.fixture
def viewer(tmp_path):
    v = mv.Viewer(cache=SpectrumCache(tmp_path / "cache"))
    v.open_mesh(SPOT)  # 2930 vertices: solved by the Krylov iteration, in this process
    return v


@pytest.fixture
def paused(monkeypatch):
    """The solve stops after its first hand-over of 12 modes or more until ``go`` is set,
    so that the test acts while modes are still to come."""
    go = threading.Event()
    solve = spectra_module.compute_spectrum

    def compute_spectrum(*args, on_modes=None, **kwargs):
        def hand_over(spec):
            on_modes(spec)
            if spec.k >= 12 and not spec.is_complete:
                go.wait(120)

        return solve(*args, on_modes=hand_over, **kwargs)

    monkeypatch.setattr(spectra_module, "compute_spectrum", compute_spectrum)
    yield go
    go.set()


def test_a_script_looks_at_the_first_modes_while_the_others_converge(viewer, paused):
    state = viewer.state
    viewer.compute("shells", k=120, wait=False)
    ready, asked = viewer.wait_for_modes(12, "shells", timeout=120)
    assert asked == 120 and 12 <= ready < 120
    spec = state.spectrum("shells")
    assert spec.k == ready and not spec.is_complete
    assert not state.has_spectrum(state.spectrum_key("shells"))
    # the first non-zero mode is on screen, as for a finished spectrum
    assert state.display.kind == "mode" and state.display.mode == 6
    # the user's choices, made while the modes arrive
    viewer.show_mode(9)
    viewer.pick_vertex(1234)
    viewer.show_distance("vibration", display="threshold", share=0.05)
    assert viewer.modes_ready("shells") == (ready, 120)  # the solve waits
    # the legend says what the map is made of, the Modes panel's note what follows
    assert f"from the first {ready} of 120 modes" in wording.legend(state)
    assert "the others follow as they converge" in wording.arrival_note(
        state.spectrum("shells"), state.spectrum_key("shells") in state.computing
    )
    chosen = state.display
    camera = {"position": (3.0, 1.0, 2.0), "focal_point": (0.0, 0.0, 0.0), "view_up": (0, 1, 0)}
    state.camera = camera
    paused.set()
    assert viewer.wait_for_modes(120, "shells", timeout=300) == (120, 120)
    final = state.spectrum("shells")
    assert final.is_complete and final.k == 120
    # the map is drawn anew from all the modes; the same kind, display and share
    kept = ("kind", "operator", "mode", "distance_kind", "distance_display", "keep_share")
    assert all(getattr(state.display, name) == getattr(chosen, name) for name in kept)
    assert state.picked == 1234 and state.camera == camera
    assert state.display.threshold_share == pytest.approx(0.05)
    dist = state.derived.distance_map()
    marked = state.derived.surface_share(dist, state.derived.threshold_value(dist))
    assert marked == pytest.approx(0.05, abs=0.01)
    assert "of 120 modes" not in wording.legend(state)
    assert (
        wording.arrival_note(
            state.spectrum("shells"), state.spectrum_key("shells") in state.computing
        )
        == ""
    )


def test_modes_relayed_by_a_child_process_equal_the_result(tmp_path):
    mesh = mv.load_mesh(SPOT)
    arrived = []
    final = compute_in_process(
        mesh, "laplacian", 80, 1.0, 1.0, tmp_path / "out.npz",
        lambda stage, fraction: None, lambda: False, arrived.append,
    )  # fmt: skip
    assert len(arrived) >= 2
    counts = [s.k for s in arrived]
    assert counts == sorted(set(counts)) and counts[-1] < 80
    assert all(not s.is_complete and s.modes_requested == 80 for s in arrived)
    last = arrived[-1]
    j = last.k
    nonzero = ~final.zero_mode_mask()[:j]
    rel = np.abs(last.eigenvalues - final.eigenvalues[:j]) / np.abs(final.eigenvalues[:j]).clip(
        1e-300
    )
    assert rel[nonzero].max() <= 1e-8
    inner = np.abs(np.einsum("v,vj,vj->j", final.mass, last.modes, final.modes[:, :j]))
    assert inner.min() >= 1 - 1e-10  # simple eigenvalues here: the same modes up to sign
    assert not list(tmp_path.glob("modalviewer-modes-*"))


def test_cancelling_mid_way_keeps_the_modes_shown_and_caches_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(spectra_module, "PROCESS_THRESHOLD", 0)  # the child process path
    cache = SpectrumCache(tmp_path / "cache")
    viewer = mv.Viewer(cache=cache)
    viewer.open_mesh(SPOT)
    job = viewer.request_spectrum("shells", k=200, show=True)
    ready, asked = viewer.wait_for_modes(8, "shells", timeout=120)
    assert 8 <= ready < asked == 200
    viewer.cancel_computation()
    viewer.wait_for(job, timeout=60)
    assert job.status == CANCELLED
    state = viewer.state
    spec = state.spectrum("shells")
    assert spec is not None and not spec.is_complete  # what had arrived stays on screen
    assert "stopped before the others" in wording.arrival_note(
        state.spectrum("shells"), state.spectrum_key("shells") in state.computing
    )
    mesh = state.compute_mesh()
    assert not cache.path(mesh, "shells", 200, 1.0, 1.0).is_file()
    assert cache.get(mesh, "shells", 200, 1.0, 1.0) is None
    # asking again computes the whole spectrum
    again = viewer.request_spectrum("shells", k=200)
    assert not again.done
    viewer.wait_for(again, timeout=300)
    assert again.status == DONE and state.spectrum("shells").is_complete


def test_the_compare_window_marks_what_is_made_of_the_first_modes(viewer):
    from dataclasses import replace as replaced

    from modalviewer.viewer.comparison import Comparison

    whole = viewer.compute("laplacian", k=30)
    first = mv.compute_spectrum(viewer.mesh, "modified_dirichlet", 30)
    part = replaced(
        first,
        eigenvalues=first.eigenvalues[:12],
        modes=first.modes[:, :12],
        residuals=first.residuals[:12],
        parameters={**first.parameters, "modes_requested": 30},
    )
    ed_key = viewer.state.compute_settings.key("modified_dirichlet", 30)
    viewer.state.add_spectrum(ed_key, part)
    compare = Comparison(viewer.state, ["laplacian", "modified_dirichlet"])
    compare.show_mode(5)
    titles = [view.title for view in compare.views()]
    assert "first 12 of 30 modes" in titles[1] and "of 30 modes" not in titles[0]
    assert viewer.state.spectrum("laplacian") is whole
