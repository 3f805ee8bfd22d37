"""Compute panel: operator, number of modes, weights, options; the mesh's load report."""

from __future__ import annotations

from qtpy import QtWidgets

from ...core.operators import OPERATOR_INFO
from ...viewer import wording
from ...viewer.viewer import Viewer
from .common import WrappingLabel, add_items, bind, combo, follow, show_values, spin_box

K_MAX = 1_000_000
"""The Modes k box's maximum: no limit a mesh could reach before the memory check."""


class ComputePanel(QtWidgets.QWidget):
    """Sets ``state.compute_settings``; the button asks the viewer to compute."""

    def __init__(self, viewer: Viewer, parent=None):
        super().__init__(parent)
        self.state = state = viewer.state
        form = QtWidgets.QFormLayout(self)
        operators = ((info.label, info.name) for info in OPERATOR_INFO.values())
        self.operator_combo = add_items(combo(), operators)
        # no cap of its own: a mesh has as many modes as unknowns (a request for more
        # gets them all and says so), and the memory check refuses what would not fit,
        # saying what would (a capped box drops typed digits beyond its cap unsaid)
        self.k_spin = spin_box(
            1,
            K_MAX,
            tip="Number of modes (lowest eigenpairs) to compute; a request that would not "
            "fit in memory is refused with what would.",
        )
        self.bending_spin, self.membrane_spin = (
            QtWidgets.QDoubleSpinBox(decimals=4, maximum=1e6) for _ in range(2)
        )
        self.rescale_check = QtWidgets.QCheckBox(
            "Rescale to unit area (default: off)",
            toolTip="Compute on a copy scaled to total area 1. The shells spectrum depends on "
            "the absolute size; rescaling makes meshes of different sizes comparable.",
        )
        self.coarse_check = QtWidgets.QCheckBox(
            "Coarse-to-fine (default: off)",
            toolTip="Compute on a copy decimated to about a fifth of the vertices and carry "
            "the modes to this mesh (paper Section 7): much faster on big meshes.",
        )
        compute_tip = "Compute the selected operator's spectrum (Ctrl+R)"
        self.compute_button = QtWidgets.QPushButton("Compute spectrum", toolTip=compute_tip)
        form.addRow("Operator", self.operator_combo)
        form.addRow("Modes k", self.k_spin)
        form.addRow("Bending weight", self.bending_spin)
        form.addRow("Membrane weight", self.membrane_spin)
        form.addRow(self.rescale_check)
        form.addRow(self.coarse_check)
        form.addRow(self.compute_button)
        self.mesh_info = WrappingLabel("No mesh")
        form.addRow(self.mesh_info)

        self.fields = {  # compute settings field -> its widget
            "operator": self.operator_combo,
            "k": self.k_spin,
            "bending": self.bending_spin,
            "membrane": self.membrane_spin,
            "rescale": self.rescale_check,
            "coarse": self.coarse_check,
        }
        for name, widget in self.fields.items():
            bind(widget, lambda value, n=name: setattr(state.compute_settings, n, value))
        self.compute_button.clicked.connect(lambda: viewer.compute(wait=False))
        follow(state, self.update_from_state, "compute_settings", "mesh")
        self.update_from_state()

    def update_from_state(self) -> None:
        s = self.state.compute_settings
        show_values((widget, getattr(s, name)) for name, widget in self.fields.items())
        weights = OPERATOR_INFO[s.operator].has_weights
        self.bending_spin.setEnabled(weights)
        self.membrane_spin.setEnabled(weights)
        mesh = self.state.mesh
        self.compute_button.setEnabled(mesh is not None)
        text = str(mesh.report) if mesh is not None else "No mesh"
        if mesh is not None and mesh.n_components > 1:
            c = mesh.n_components
            text += (
                f"\n{c} connected components: every spectrum starts with zero modes per "
                f"component ({c} for the Laplacian, {6 * c} rigid motions for the shells). "
                "Mesh > Keep the largest component, or compute more modes."
            )
        if mesh is not None and mesh.n_face_components > mesh.n_components:
            joined = mesh.n_face_components - mesh.n_components
            text += (
                f"\n{joined} {'parts meet' if joined > 1 else 'part meets'} the rest only at "
                "vertices: "
                "a part held at a single vertex can rotate about it (three more zero modes "
                "for the shells)."
            )
        note = wording.negative_weights_note(self.state)
        if note:
            text += "\n" + note
        self.mesh_info.setText(text)
