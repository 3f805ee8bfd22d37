"""File > Export spectrum writes the spectrum the picture on screen is made of."""

from pathlib import Path

from modalviewer.core.cache import SpectrumCache
from modalviewer.gui.file_dialogs import spectrum_to_export
from modalviewer.viewer import ViewerModel

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def test_the_exported_spectrum_is_the_one_on_screen(tmp_path):
    # with a vibration distance on screen and the Laplacian computed after it (as the
    # distance comparison does), the export took the Laplacian
    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(ASSETS / "demo_plate.obj")
    state = model.state
    model.jobs.wait(model.request_spectrum("shells", k=12, show=True))
    state.show_mode(8)
    assert spectrum_to_export(state).operator == "shells"
    state.set_display(kind="distance", distance_kind="vibration")
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=False))
    assert spectrum_to_export(state).operator == "shells"
    state.set_display(distance_kind="hks")
    assert spectrum_to_export(state).operator == "laplacian"
    state.show_mode(3, "laplacian")
    assert spectrum_to_export(state).operator == "laplacian"
