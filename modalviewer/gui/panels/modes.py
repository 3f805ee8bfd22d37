"""Modes panel: which spectrum, which mode, its eigenvalue, the spectrum plot, isolines."""

from __future__ import annotations

import numpy as np
from qtpy import QtWidgets

from ...core.operators import DISTANCE_KINDS, OPERATOR_INFO
from ...viewer.state import ViewerState
from ...viewer.viewer import Viewer
from ...viewer.wording import approximation_mark, arrival_note
from ..plots import LinePlot
from .common import (
    WrappingLabel,
    add_items,
    bind,
    combo,
    describe,
    follow,
    quiet,
    row,
    select_data,
    show_values,
    slider,
    spin_box,
)


class ModesPanel(QtWidgets.QWidget):
    """Shows and sets ``state.display`` for modes and ``state.style``; while the surface
    shows something else, it says so instead of naming a mode not on screen."""

    def __init__(self, viewer: Viewer, parent=None):
        super().__init__(parent)
        self.state = state = viewer.state
        lay = QtWidgets.QVBoxLayout(self)
        self.spectrum_combo = combo()
        describe(self.spectrum_combo, "The computed spectrum whose modes are shown")
        lay.addLayout(row("Spectrum", (self.spectrum_combo, 1)))
        self.mode_slider = slider(0, 0, "Mode index (arrow keys step while the slider has focus)")
        self.mode_spin = QtWidgets.QSpinBox()
        lay.addLayout(row("Mode", (self.mode_slider, 1), self.mode_spin))
        self.eigen_label = WrappingLabel("No spectrum yet.")
        lay.addWidget(self.eigen_label)
        self.spectrum_plot = LinePlot("Spectrum", "mode index", "\u03bb")
        lay.addWidget(self.spectrum_plot)
        form = QtWidgets.QFormLayout()
        self.color_combo = add_items(
            combo(),
            (
                ("Deformed shape", "deformed", "Displaced by the mode, coloured by its |Phi|"),
                ("Normal component on rest shape", "normal", "Signed, along smoothed normals"),
                ("Magnitude on rest shape", "magnitude", "|displacement| on the rest shape"),
            ),
        )
        describe(self.color_combo, "How 3D vibration modes are shown")
        self.iso_spin = spin_box(0, 60, tip="Number of isolines (0: none)")
        form.addRow("Show 3D modes as", self.color_combo)
        form.addRow("Isolines", self.iso_spin)
        lay.addLayout(form)

        # the chosen spectrum's mode last shown, or its first non-zero mode
        self.spectrum_combo.activated.connect(
            lambda _: viewer.show_current_mode(self.spectrum_combo.currentData())
        )
        for signal in (
            self.mode_slider.valueChanged,
            self.mode_spin.valueChanged,
            self.spectrum_plot.sampleClicked,
        ):
            signal.connect(viewer.show_mode)
        self.style_fields = {"shell_coloring": self.color_combo, "isolines": self.iso_spin}
        for name, widget in self.style_fields.items():
            bind(widget, lambda value, n=name: setattr(state.style, n, value))
        follow(state, self.update_from_state, "display", "spectra", "mesh")
        state.events.style.connect(self._update_style)
        self.update_from_state()
        self._update_style()

    def update_from_state(self, *_args) -> None:
        state = self.state
        computed = state.operators_computed()
        op = state.current_operator()
        with quiet(self.spectrum_combo, self.mode_slider, self.mode_spin):
            self.spectrum_combo.clear()
            for name in computed:
                info = OPERATOR_INFO[name]
                mark = approximation_mark(state.spectrum(name), state.is_coarse(name))
                # marked: the short name, so the mark is not cut off in a narrow panel
                label = (info.short_label if mark else info.label) + mark
                add_items(self.spectrum_combo, [(label, name, info.label + mark)])
            if op is not None:
                select_data(self.spectrum_combo, op)
            spec = state.spectrum(op)
            k = spec.k if spec is not None else 1
            self.mode_slider.setRange(0, k - 1)
            self.mode_spin.setRange(0, k - 1)
            showing_mode = state.display.kind == "mode" and spec is not None
            if spec is not None and state.display.operator == op:
                # the mode shown, or last shown (M shows it again)
                self.mode_slider.setValue(state.display.mode)
                self.mode_spin.setValue(state.display.mode)
        for w in (self.spectrum_combo, self.mode_slider, self.mode_spin):
            w.setEnabled(spec is not None)
        if spec is None:
            self.eigen_label.setText("No spectrum yet: compute one (Ctrl+R).")
            self.spectrum_plot.set_data([], [], title="Spectrum")
            return
        zero = spec.zero_mode_mask()
        if showing_mode:
            j = min(state.display.mode, spec.k - 1)
            lam = float(spec.eigenvalues[j])
            if zero[j]:
                text = f"lambda_{j} = 0 (zero mode)"
            else:
                text = f"lambda_{j} = {lam:.6g}   sqrt(lambda) = {np.sqrt(max(lam, 0.0)):.6g}"
        else:
            # short (two lines), so the rows below stay in view beside a note: the view's
            # title says the rest (from which vertex, which scales)
            text = f"Not shown (M shows it): {_what_is_shown(state)} on screen."
        if state.is_coarse(op):
            text += (
                "\nCoarse-to-fine: computed on a copy decimated to about a fifth and carried "
                "to this mesh; eigenvalues and modes approximate (untick Coarse-to-fine and "
                "Compute for the exact spectrum)."
            )
        arriving = arrival_note(spec, state.spectrum_key(op) in state.computing)
        if arriving:
            text += f"\n{arriving}"
        self.eigen_label.setText(text)
        approximate = approximation_mark(spec, state.is_coarse(op))
        # marked: the short name (as in the spectrum list), so the title keeps to one line
        info = OPERATOR_INFO[op]
        self.spectrum_plot.set_data(
            np.arange(spec.k),
            np.where(zero, 0.0, spec.eigenvalues),
            state.display.mode if showing_mode else None,
            title=f"Spectrum{approximate}: {info.short_label if approximate else info.label}",
        )

    def _update_style(self) -> None:
        style = self.state.style
        show_values((w, getattr(style, name)) for name, w in self.style_fields.items())


def _what_is_shown(state: ViewerState) -> str:
    """The field on screen in a few words, for a panel that is not the one on screen
    (the view's title names it in full: from which vertex, at which scales)."""
    d = state.display
    if d.kind == "distance":
        how = "threshold map" if d.distance_display == "threshold" else "map"
        return f"{DISTANCE_KINDS[d.distance_kind].lower()} {how}"
    if d.kind == "signature":
        return f"{DISTANCE_KINDS[d.distance_kind].split()[0].lower()} signature"
    if d.kind == "curvature":
        return "curvature"
    return "no field"
