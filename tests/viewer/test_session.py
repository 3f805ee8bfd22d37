"""Session files: save and restore the state (no Qt)."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from modalviewer.core.cache import SpectrumCache
from modalviewer.viewer import ViewerModel, wording
from modalviewer.viewer.session import SessionError, restore_session, save_session

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def _model(tmp_path):
    return ViewerModel(cache=SpectrumCache(tmp_path / "cache"))


def _wait_all(model, restored):
    for job in restored.jobs:
        model.jobs.wait(job)


def test_a_restored_session_shows_the_same_picture(tmp_path):
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    first = _model(tmp_path)
    first.open_mesh(mesh_path)
    s = first.state
    first.jobs.wait(first.request_spectrum("laplacian", k=25))
    s.style.isolines = 7
    s.set_scale_range((0.01, 2.0))
    s.set_pick(321)
    s.set_display(kind="distance", distance_kind="hks", distance_display="threshold")
    s.set_display(threshold=s.derived.threshold_for_share(0.15))
    s.camera = {"position": [1, 2, 3], "focal_point": [0, 0, 0], "view_up": [0, 1, 0]}
    path = save_session(s, tmp_path / "a.json")
    data = json.loads(path.read_text())
    assert data["version"] == 2 and data["mesh"]["hash"] == first.state.mesh.hash

    second = _model(tmp_path)  # same cache: the spectrum comes back from disk
    restored = restore_session(second, path)
    _wait_all(second, restored)
    t = second.state
    assert restored.notes == []
    assert t.display == s.display and t.picked == 321 and t.t_range == (0.01, 2.0)
    assert t.style.isolines == 7 and t.camera == s.camera
    np.testing.assert_array_equal(t.derived.field().values, s.derived.field().values)
    assert wording.legend(t) == wording.legend(s)


def test_a_session_whose_mesh_changed_says_so_and_opens_what_it_can(tmp_path):
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    model = _model(tmp_path)
    model.open_mesh(mesh_path)
    model.jobs.wait(model.request_spectrum("laplacian", k=12, show=True))
    model.state.set_pick(2900)
    path = save_session(model.state, tmp_path / "b.json")
    # the file is replaced by a smaller mesh
    shutil.copy(ASSETS / "demo_plate.obj", mesh_path)
    other = _model(tmp_path)
    restored = restore_session(other, path)
    _wait_all(other, restored)
    assert any("changed on disk" in note for note in restored.notes)
    assert any("picked vertex 2900" in note for note in restored.notes)
    assert other.state.mesh is not None and other.state.picked is None
    assert other.state.display.kind == "mode"  # the spectrum was recomputed


def test_bad_session_files_raise_clear_errors(tmp_path):
    model = _model(tmp_path)
    junk = tmp_path / "junk.json"
    junk.write_text("{not json")
    with pytest.raises(SessionError, match="not a readable session"):
        restore_session(model, junk)
    junk.write_text(json.dumps({"format": "modalviewer-session", "version": 99}))
    with pytest.raises(SessionError, match="newer modalviewer"):
        restore_session(model, junk)
    junk.write_text(json.dumps({"format": "something else"}))
    with pytest.raises(SessionError, match="not a modalviewer session"):
        restore_session(model, junk)
    assert model.state.mesh is None  # nothing was half-loaded


def test_session_files_get_the_umask_permissions(tmp_path):
    import os

    model = _model(tmp_path)
    model.open_mesh(ASSETS / "spot.obj")
    old = os.umask(0o022)
    try:
        path = save_session(model.state, tmp_path / "perm.json")
    finally:
        os.umask(old)
    assert (path.stat().st_mode & 0o777) == 0o644
    assert not list(tmp_path.glob(".perm.json.*"))  # no temporary file left


def test_a_session_keeps_the_chosen_up_axis(tmp_path):
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    first = _model(tmp_path)
    first.open_mesh(mesh_path)
    first.state.up_axis = "+z"
    path = save_session(first.state, tmp_path / "up.json")
    assert json.loads(path.read_text())["up_axis"] == "+z"
    second = _model(tmp_path)
    restored = restore_session(second, path)
    assert restored.notes == [] and second.state.up_axis == "+z"
    # an automatic axis stays automatic; a damaged value is a note, not a failure
    first.state.up_axis = None
    data = json.loads(save_session(first.state, tmp_path / "auto.json").read_text())
    assert data["up_axis"] is None
    data["up_axis"] = "sideways"
    (tmp_path / "bad.json").write_text(json.dumps(data))
    third = _model(tmp_path)
    restored = restore_session(third, tmp_path / "bad.json")
    assert third.state.up_axis is None and any("up axis" in n for n in restored.notes)


def test_a_session_naming_the_removed_preview_options_opens_without_them(tmp_path):
    """Sessions saved while the viewer offered previews hold "preview" and
    "preview_only" among the compute settings: they open, with the other settings."""
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    first = _model(tmp_path)
    first.open_mesh(mesh_path)
    first.state.compute_settings.operator = "laplacian"
    first.state.compute_settings.k = 25
    first.state.compute_settings.coarse = True
    path = save_session(first.state, tmp_path / "old.json")
    data = json.loads(path.read_text())
    data["compute_settings"].update(preview=True, preview_only=True)
    path.write_text(json.dumps(data))
    second = _model(tmp_path)
    restored = restore_session(second, path)
    _wait_all(second, restored)
    assert restored.notes == []
    settings = second.state.compute_settings
    assert (settings.operator, settings.k, settings.coarse) == ("laplacian", 25, True)
    assert not hasattr(settings, "preview")


def test_restored_spectra_keep_their_keys_and_the_compute_settings_stay_as_saved(tmp_path):
    """Each saved spectrum is requested under its own key (Discrete Shells weights, unit
    area), whatever the saved compute settings say; those come back unchanged."""
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    first = _model(tmp_path)
    first.open_mesh(mesh_path)
    settings = first.state.compute_settings
    settings.bending, settings.membrane, settings.rescale = 2.0, 0.5, True
    first.jobs.wait(first.request_spectrum("shells", k=8))
    settings.bending, settings.membrane, settings.rescale = 1.0, 1.0, False
    first.jobs.wait(first.request_spectrum("laplacian", k=10))
    settings.operator, settings.k, settings.coarse = "modified_dirichlet", 30, True
    path = save_session(first.state, tmp_path / "keys.json")

    second = _model(tmp_path)
    restored = restore_session(second, path)
    _wait_all(second, restored)
    assert restored.notes == []
    assert set(second.state.spectra) == set(first.state.spectra)
    shells = second.state.spectrum_key("shells")
    assert (shells.k, shells.bending, shells.membrane, shells.rescale) == (8, 2.0, 0.5, True)
    restored_settings = second.state.compute_settings
    assert restored_settings == first.state.compute_settings
    assert restored_settings.coarse and restored_settings.k == 30


def test_a_session_naming_an_unknown_operator_opens_what_it_can_and_says_what_not(tmp_path):
    """A session from a version with another operator (or edited by hand): the mesh and
    the other spectra open; each spectrum that cannot be asked for is a note naming it,
    and compute settings naming no known operator fall back to the defaults with a note."""
    mesh_path = tmp_path / "spot.obj"
    shutil.copy(ASSETS / "spot.obj", mesh_path)
    first = _model(tmp_path)
    first.open_mesh(mesh_path)
    first.jobs.wait(first.request_spectrum("laplacian", k=10))
    path = save_session(first.state, tmp_path / "s.json")
    data = json.loads(path.read_text())
    data["spectra"] += [{"operator": "biharmonic_2030", "k": 12}, {"k": 12}]
    data["compute_settings"]["operator"] = "biharmonic_2030"
    path.write_text(json.dumps(data))

    second = _model(tmp_path)
    restored = restore_session(second, path)
    _wait_all(second, restored)
    assert [key.operator for key in second.state.spectra] == ["laplacian"]
    unknown = [note for note in restored.notes if "biharmonic_2030" in note]
    assert len(unknown) == 2, restored.notes  # the spectrum and the compute settings
    assert any(
        "{'k': 12} is not computed" in note and "'operator'" in note for note in restored.notes
    )
    assert second.state.compute_settings.operator == "modified_dirichlet"  # the default
    assert second.state.compute_settings.k == first.state.compute_settings.k  # kept
    assert len(restored.notes) == 3, restored.notes
