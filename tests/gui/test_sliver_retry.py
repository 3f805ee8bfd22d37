"""A shells spectrum refused on sliver triangles: the error offers "Fix slivers and
retry", which repairs the mesh, shows the report and computes the same spectrum again."""

import sys

import pytest
from qtpy import QtWidgets

import modalviewer as mv
from benchmarks.slivers import add_slivers
from modalviewer.core.primitives import icosphere
from modalviewer.repair import repair_for_failure


@pytest.fixture(scope="module")
def slivered():
    v, f = add_slivers(icosphere(3), needles=20, caps=20, eps=1e-8, seed=2)
    return mv.Mesh(v, f)


def _fail_on_slivers(window, qtbot, mesh, monkeypatch):
    monkeypatch.delenv("MODALVIEWER_NO_DIALOGS")  # the real dialogs
    window.set_mesh(mesh)
    window.compute("shells", k=12, wait=False)
    qtbot.waitUntil(lambda: window.sliver_failure is not None, timeout=60000)
    box = window.message_box
    assert box is not None and box.isVisible()
    assert "could not be factorised" in box.text() and "sliver" in box.text()
    return box


def test_fix_slivers_and_retry_repairs_and_computes_the_same_spectrum(
    window, qtbot, slivered, monkeypatch
):
    box = _fail_on_slivers(window, qtbot, slivered, monkeypatch)
    button = box.defaultButton()
    assert button.text() == "Fix slivers and retry"  # the default: what was asked for
    assert window.spectra == {}
    button.click()
    # the whole spectrum, not its first modes
    qtbot.waitUntil(lambda: window.state.modes_ready("shells") == (12, 12), timeout=120000)
    mesh = window.mesh
    assert isinstance(mesh.report, mv.SliverReport) and mesh is not slivered
    assert mesh.report.slivers_after == 0 and window.state.mesh_repairs == ["fix_slivers"]
    spec = window.state.spectrum("shells")
    assert spec.k == 12 and spec.mesh_hash == mesh.hash
    assert window.sliver_failure is None
    report = window.message_box
    assert report.windowTitle() == "Slivers fixed" and "Changed" in report.text()
    assert "Discrete Shells (3D vibrations), 12 modes again" in report.text()


def test_without_pymeshlab_the_button_says_how_to_install_it(window, qtbot, slivered, monkeypatch):
    box = _fail_on_slivers(window, qtbot, slivered, monkeypatch)
    monkeypatch.setitem(sys.modules, "pymeshlab", None)  # import pymeshlab fails
    box.defaultButton().click()
    hint = window.message_box
    assert hint is not box and hint.isVisible()
    assert "pip install 'modalviewer[repair]'" in hint.text() and "pymeshlab" in hint.text()
    assert window.mesh is slivered and window.viewer.jobs.jobs == []  # nothing started
    assert isinstance(hint, QtWidgets.QMessageBox)


def test_only_factorisation_failures_on_slivers_offer_the_fix():
    assert (
        repair_for_failure(
            "the operator could not be factorised even with a shift below zero: it is "
            "numerically indefinite; if the mesh has nearly degenerate (sliver) triangles, ..."
        )
        == "fix_slivers"
    )
    assert repair_for_failure("Not enough memory for this computation") is None
    assert repair_for_failure(None) is None
