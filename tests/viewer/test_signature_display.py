"""The signature display: a typed scale, the log colouring, and the truncation estimate
in the legend and status line when it is large."""

import numpy as np
import pytest

from modalviewer.core.primitives import torus
from modalviewer.core.signatures import default_times, signature
from modalviewer.core.truncation import truncation_error
from modalviewer.viewer import Viewer, wording


@pytest.fixture
def viewer():
    v = Viewer()
    v.set_mesh(torus(16, 8))
    v.state.set_display(distance_kind="feature")
    v.compute("modified_dirichlet", k=20)
    yield v
    v.close()


def test_a_typed_scale_is_shown_itself_and_a_sample_replaces_it(viewer):
    state = viewer.state
    spec = state.spectrum("modified_dirichlet")
    times = default_times(spec)
    t = float(np.sqrt(times[10] * times[11]))  # between two samples
    viewer.show_signature_at(t)
    assert state.derived.signature_time() == t
    assert state.display.signature_sample in (10, 11)
    field = state.derived.field()
    np.testing.assert_allclose(field.values, signature(spec, [t])[1][:, 0])
    assert f"t = {t:.3g}" in field.legend
    viewer.show_signature(30)
    assert state.display.signature_time is None
    assert state.derived.signature_time() == pytest.approx(times[30])
    with pytest.raises(ValueError, match="positive"):
        state.set_display(signature_time=-1.0)


def test_the_log_colouring_shows_log10_over_the_smallest_value(viewer):
    state = viewer.state
    viewer.show_signature(40)
    plain = state.derived.field().values
    state.style.log_signature = True
    field = state.derived.field()
    np.testing.assert_allclose(field.values, np.log10(plain / plain.min()))
    assert field.values.min() == 0
    assert "log10" in field.legend


def test_a_large_truncation_error_is_in_the_legend_and_status_with_a_k(viewer):
    state = viewer.state
    spec = state.spectrum("modified_dirichlet")
    viewer.show_signature(50)
    assert "truncation" not in wording.legend(state)
    small = 0.05 * default_times(spec)[0]  # typed far below the default scales
    viewer.show_signature_at(small)
    error, k = state.derived.truncation()
    assert error == pytest.approx(truncation_error(spec, [small])[0])
    assert error > 0.05 and k > spec.k
    legend = wording.legend(state)
    assert "truncation: about" in legend and f"k = {k} for <" in legend
    assert "truncation: about" in wording.summary(state)
