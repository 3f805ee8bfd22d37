"""File > Open collection...: the store's shapes nearest to the mesh on screen, and the
chosen one opened beside it in the shape-pair window."""

import numpy as np
import pytest

import modalviewer as mv
from modalviewer import collection as coll
from modalviewer.core import primitives

pytestmark = pytest.mark.gui


def _write_obj(mesh, path):
    with open(path, "w") as fh:
        for x, y, z in mesh.vertices:
            fh.write(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n")
        for a, b, c in mesh.faces + 1:
            fh.write(f"f {a} {b} {c}\n")


def test_open_collection_lists_nearest_and_opens_beside(window, tmp_path):
    from modalviewer.gui.collection_dialog import open_collection_window

    folder = tmp_path / "meshes"
    folder.mkdir()
    torus = primitives.torus(14, 7)
    _write_obj(torus, folder / "torus.obj")
    c, s = np.cos(0.5), np.sin(0.5)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    _write_obj(mv.Mesh(torus.vertices @ turn.T + 1.0, torus.faces), folder / "turned.obj")
    _write_obj(primitives.icosphere(1), folder / "sphere.obj")
    _write_obj(primitives.grid_plate(6, 5), folder / "plate.obj")
    store = tmp_path / "store"
    coll.run_batch([folder], store, "laplacian", 8, workers=0)
    assert window.open_mesh(folder / "torus.obj")
    dialog = open_collection_window(window, store)
    assert dialog is not None and dialog.isVisible()
    labels = [dialog.list.item(i).text() for i in range(dialog.list.count())]
    assert labels[0].startswith("torus") and labels[1].startswith("turned")
    dialog.list.setCurrentRow(1)
    pair = dialog.open_selected(wait=True)
    assert pair is window.pair_window and pair.pair.sides["b"].name == "turned.obj"
    pair.close()
    dialog.close()


def test_a_mesh_outside_the_store_is_ranked_once_its_spectrum_is_in(window, qtbot, tmp_path):
    from modalviewer.gui.collection_dialog import open_collection_window

    folder = tmp_path / "meshes"
    folder.mkdir()
    _write_obj(primitives.torus(14, 7), folder / "torus.obj")
    _write_obj(primitives.grid_plate(6, 5), folder / "plate.obj")
    store = tmp_path / "store"
    coll.run_batch([folder], store, "laplacian", 8, workers=0)
    outside = tmp_path / "moved_torus.obj"
    torus = primitives.torus(14, 7)
    _write_obj(mv.Mesh(torus.vertices + [0.0, 0.0, 3.0], torus.faces), outside)
    assert window.open_mesh(outside)
    assert open_collection_window(window, store) is None  # the spectrum is computed first
    qtbot.waitUntil(lambda: getattr(window, "collection_dialog", None) is not None, timeout=30000)
    dialog = window.collection_dialog
    assert dialog.list.item(0).text().startswith("torus")
    assert window.state.spectrum("laplacian").k >= 8
    dialog.close()


def test_not_a_collection_is_a_message(window, tmp_path):
    from modalviewer.gui.collection_dialog import open_collection_window

    assert open_collection_window(window, tmp_path) is None
    assert "not a collection" in window.last_error
