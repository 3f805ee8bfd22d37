"""File > Open collection...: a store of ``modalviewer batch`` listed nearest to the mesh
on screen first; the chosen shape opens beside it in the shape-pair window.  The list
comes from :func:`modalviewer.collection.nearest_rows` (no Qt)."""

from __future__ import annotations

from pathlib import Path

from qtpy import QtCore, QtWidgets

from ..collection import CollectionError, nearest_rows, open_collection
from ..core.operators import operator_info
from .pair_window import open_pair_window


class CollectionDialog(QtWidgets.QDialog):
    """The shapes of a collection, nearest first; "Open beside" opens the selected one
    as mesh B of the shape-pair window."""

    def __init__(self, main, collection, rows):
        super().__init__(main, windowTitle=f"Collection {collection.path.name}")
        self.main, self.collection, self.rows = main, collection, rows
        layout = QtWidgets.QVBoxLayout(self)
        nearest = main.state.mesh is not None
        what = "nearest to the mesh on screen first" if nearest else "open a mesh to rank them"
        self.header = QtWidgets.QLabel(
            f"{len(collection.names)} shapes ({collection.operator}, {collection.k} modes), "
            f"{what}; Shape-DNA distance"
            + (f"; {len(collection.errors)} failed in the batch" if collection.errors else "")
        )
        self.header.setWordWrap(True)
        layout.addWidget(self.header)
        self.list = QtWidgets.QListWidget()
        for row in rows:
            item = QtWidgets.QListWidgetItem(row.label)
            if not row.available:
                item.setFlags(item.flags() & ~QtCore.Qt.ItemFlag.ItemIsEnabled)
            self.list.addItem(item)
        self.list.itemDoubleClicked.connect(lambda _: self.open_selected())
        layout.addWidget(self.list)
        buttons = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.StandardButton.Close)
        self.open_button = buttons.addButton(
            "Open beside", QtWidgets.QDialogButtonBox.ButtonRole.ActionRole
        )
        self.open_button.setEnabled(nearest)
        self.open_button.clicked.connect(self.open_selected)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        first = next((i for i, row in enumerate(rows) if row.available), None)
        if first is not None:
            self.list.setCurrentRow(first)
        self.resize(520, 420)

    def open_selected(self, wait: bool = False):
        """Open the selected shape beside the mesh on screen (the pair window)."""
        i = self.list.currentRow()
        if i < 0 or not self.rows[i].available or self.main.state.mesh is None:
            return None
        return open_pair_window(self.main, self.rows[i].source, wait=wait)


def open_collection_window(main, path) -> CollectionDialog | None:
    """The dialog of the store at ``path``, shown; None (after a message) if it is not
    a collection.  The distances need the mesh on screen's spectrum of the store's
    operator: the stored one if the store holds the mesh, else the one on screen if it
    has the store's k modes; else the viewer computes it in the background and the
    dialog opens when it is in (None is returned then)."""
    try:
        collection = open_collection(path)
    except (CollectionError, OSError) as exc:
        main.show_error(str(exc), "Cannot open collection")
        return None
    mesh = main.state.mesh
    spectrum = main.state.spectrum(collection.operator)
    stored = (collection.info["bending"], collection.info["membrane"])
    weights = operator_info(collection.operator).has_weights and stored != (1.0, 1.0)
    if mesh is not None and collection.needs_spectrum(mesh, spectrum) and not weights:
        # the viewer computes it in the background (and caches it); the list follows
        main.statusBar().showMessage(
            f"Computing the {collection.operator} spectrum ({collection.k} modes) to rank "
            f"{collection.path.name}...",
            8000,
        )
        main.compute(
            collection.operator,
            collection.k,
            wait=False,
            then=lambda spec: _show(main, collection, mesh, spec),
        )
        return None
    return _show(main, collection, mesh, spectrum)


def _show(main, collection, mesh, spectrum) -> CollectionDialog | None:
    if mesh is not main.state.mesh:  # another mesh was opened meanwhile
        return None
    QtWidgets.QApplication.setOverrideCursor(QtCore.Qt.CursorShape.WaitCursor)
    try:
        rows = nearest_rows(collection, mesh, spectrum)
    except (ValueError, RuntimeError, MemoryError) as exc:
        main.show_error(f"Cannot rank the collection: {exc}", "Open collection")
        return None
    finally:
        QtWidgets.QApplication.restoreOverrideCursor()
    dialog = CollectionDialog(main, collection, rows)
    main.collection_dialog = dialog
    dialog.show()
    return dialog


def open_collection_dialog(main) -> None:
    """File > Open collection...: choose the store folder."""
    start = str(main.settings.value("files/collection_dir", str(Path.home())))
    path = QtWidgets.QFileDialog.getExistingDirectory(main, "Open collection", start)
    if path:
        if main.remember_settings:
            main.settings.setValue("files/collection_dir", str(Path(path).parent))
        open_collection_window(main, path)
