"""The state's values, the values derived from them and the words: the explicit
threshold-share rule, the derived caches and the wording functions (no Qt)."""

from pathlib import Path

import numpy as np
import pytest

from modalviewer import multiscale_distance
from modalviewer.core.cache import SpectrumCache
from modalviewer.core.laplacian import lumped_masses, vertex_normals
from modalviewer.core.mesh import Mesh
from modalviewer.core.primitives import icosphere
from modalviewer.core.signatures import default_times
from modalviewer.viewer import ViewerModel, wording
from modalviewer.viewer.derived import DerivedValues
from modalviewer.viewer.state import DEFAULT_THRESHOLD_SHARE

ASSETS = Path(__file__).resolve().parents[2] / "assets"


@pytest.fixture
def model(tmp_path):
    m = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    m.open_mesh(ASSETS / "spot.obj")
    return m


def marked(state) -> float:
    """The share of the surface's area the threshold map marks, computed here."""
    areas = lumped_masses(state.mesh)
    d = state.derived.distance_map()
    return float(areas[d <= state.display.threshold * d.max()].sum() / areas.sum())


def test_the_state_owns_the_one_derived_object(model):
    derived = model.state.derived
    assert isinstance(derived, DerivedValues)
    assert model.state.derived is derived and derived.state is model.state
    assert not hasattr(model, "derived")  # no second name for it


def test_a_share_set_by_the_user_is_kept_across_a_new_pick_and_a_new_spectrum(model):
    state = model.state
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_pick(10)
    state.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    assert state.display.threshold_share == DEFAULT_THRESHOLD_SHARE
    assert marked(state) == pytest.approx(DEFAULT_THRESHOLD_SHARE, abs=0.01)
    state.set_display(threshold_share=0.3)
    assert state.display.threshold_share == 0.3
    assert marked(state) == pytest.approx(0.3, abs=0.01)
    fraction = state.display.threshold
    state.set_pick(2000)
    assert state.display.threshold_share == 0.3 and state.display.keep_share
    assert marked(state) == pytest.approx(0.3, abs=0.01)
    assert state.threshold_map == state.derived.map_identity()
    model.jobs.wait(model.request_spectrum("laplacian", k=40))  # another spectrum
    assert state.spectrum("laplacian").k == 40
    assert state.display.threshold_share == 0.3
    assert marked(state) == pytest.approx(0.3, abs=0.01)
    assert state.derived.marked_share() == pytest.approx(marked(state), abs=1e-12)
    assert fraction > 0  # the fraction is whatever marks the share on each map


def test_a_fraction_set_explicitly_is_kept_as_a_fraction(model):
    state = model.state
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_pick(10)
    state.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    # on the map on screen: the fraction stays, the share is the one it marks
    state.set_display(threshold=0.4)
    assert state.display.threshold == 0.4
    assert state.display.threshold_share == pytest.approx(marked(state), abs=1e-12)
    # by value: a new pick keeps the fraction, the share follows it
    state.set_display(keep_share=False)
    state.set_pick(1500)
    assert state.display.threshold == 0.4
    assert state.display.threshold_share == pytest.approx(marked(state), abs=1e-12)
    # a fraction set while no threshold map is on screen is kept for the next map
    state.set_display(keep_share=True, kind="none")
    state.set_display(threshold=0.25)
    assert state.display.threshold == 0.25
    state.set_display(kind="distance")
    assert state.display.threshold == 0.25
    share = state.display.threshold_share
    assert share == pytest.approx(marked(state), abs=1e-12)
    state.set_pick(300)  # and later maps keep the share it marked
    assert state.display.threshold_share == share
    assert marked(state) == pytest.approx(share, abs=0.01)


def test_the_derived_values_follow_the_mesh_the_spectra_and_the_pick(model):
    state, derived = model.state, model.state.derived
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_display(kind="distance", distance_kind="hks")
    assert derived.distance_map() is None  # no pick yet
    state.set_pick(10)
    spec = state.spectrum("laplacian")
    np.testing.assert_allclose(derived.distance_map(), multiscale_distance(spec, 10), atol=1e-12)
    state.set_pick(700)  # another pick
    np.testing.assert_allclose(derived.distance_map(), multiscale_distance(spec, 700), atol=1e-12)
    state.set_scale_range((0.01, 1.0))  # another scale range
    np.testing.assert_allclose(
        derived.distance_map(), multiscale_distance(spec, 700, (0.01, 1.0)), atol=1e-12
    )
    assert derived.scale_limits() == pytest.approx((0.01, 1.0))
    state.set_scale_range(None)
    model.jobs.wait(model.request_spectrum("laplacian", k=20))  # another spectrum
    other = state.spectrum("laplacian")
    assert other is not spec and other.k == 20
    np.testing.assert_allclose(derived.distance_map(), multiscale_distance(other, 700), atol=1e-12)
    np.testing.assert_allclose(derived.table("laplacian").times, default_times(other, 100))
    # another mesh: no spectrum, no pick; its own normals and areas
    sphere = icosphere(3)
    mesh = Mesh(sphere.vertices * 2.0, sphere.faces)
    model.set_mesh(mesh)
    assert derived.distance_map() is None and derived.field().colormap == "plain"
    np.testing.assert_allclose(derived.normals, vertex_normals(mesh), atol=1e-12)
    np.testing.assert_allclose(derived.vertex_areas(), lumped_masses(mesh), atol=1e-12)
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.set_pick(5)
    spec = state.spectrum("laplacian")
    assert spec.n_vertices == mesh.n_vertices
    np.testing.assert_allclose(derived.distance_map(), multiscale_distance(spec, 5), atol=1e-12)
    assert state.display.kind == "none"  # a new mesh shows nothing at first
    state.set_display(kind="distance")
    field = derived.field()
    assert field.colormap == "sequential"
    np.testing.assert_array_equal(field.values, derived.distance_map())


def test_the_wording_functions_give_the_legends_they_gave_as_state_methods(tmp_path):
    """The texts below were produced by ``ViewerState.legend`` before the wording moved
    to :mod:`modalviewer.viewer.wording`, for the same steps."""
    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(ASSETS / "spot.obj")
    state = model.state
    model.jobs.wait(model.request_spectrum("laplacian", k=30))
    state.show_mode(5, "laplacian")
    mode_text = "Laplacian (cotan), mode 5: lambda = 10.75\nblue +, white 0, orange -"
    assert wording.legend(state) == mode_text
    # the picture's legend also names the colour range
    assert model.state.derived.field().legend == mode_text + "\nrange: the largest |value|"
    assert wording.summary(state) == mode_text.replace("\n", "; ")
    state.set_pick(100)
    state.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    threshold_text = "blue: heat kernel distance < 0.0621, 10.0 % of the surface\nfrom vertex 100"
    assert wording.legend(state) == threshold_text
    assert model.state.derived.field().legend == threshold_text
    assert wording.display_mark(state) == ""
    assert (
        wording.approximation_note(state.spectrum("laplacian"), state.is_coarse("laplacian")) == ""
    )
