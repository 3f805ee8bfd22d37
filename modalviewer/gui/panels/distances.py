"""Distances panel: kind, continuous or threshold, the threshold, scale range, signature."""

from __future__ import annotations

from qtpy import QtGui, QtWidgets

from ...core.operators import DISTANCE_KINDS, OPERATOR_INFO, operator_for_distance
from ...viewer.state import DISTANCE_DISPLAYS
from ...viewer.viewer import Viewer
from ..plots import LinePlot
from .common import (
    WrappingLabel,
    add_items,
    bind,
    combo,
    follow,
    quiet,
    row,
    show_values,
    slider,
)

SLIDER_STEPS = 1000


class DistancesPanel(QtWidgets.QWidget):
    """Shows and sets the distance part of ``state.display`` and the scale range.  The
    threshold slider moves by default through the share of the surface marked similar (a
    quantile), so its whole travel is useful whatever the distribution; "by value" makes
    it linear in the fraction of the largest distance.  Actions needing a spectrum go to
    the viewer."""

    def __init__(self, viewer: Viewer, parent=None):
        super().__init__(parent)
        self.viewer = viewer
        self.state = state = viewer.state
        form = QtWidgets.QFormLayout(self)
        self.kind_combo = add_items(combo(), ((v, k) for k, v in DISTANCE_KINDS.items()))
        displays = ("Continuous (white to red)", "Threshold (blue = similar)")
        self.display_combo = add_items(combo(), zip(displays, DISTANCE_DISPLAYS, strict=True))
        self.threshold_slider = slider(1, SLIDER_STEPS, "Threshold of the blue (similar) region")
        self.by_share_check = QtWidgets.QCheckBox(
            "Slider by share of surface",
            checked=True,
            toolTip="On: the slider moves through the share of the surface marked similar. "
            "Off: linear in the fraction of the largest distance.",
        )
        self.threshold_label = WrappingLabel("-")
        self.threshold_slider.setSingleStep(5)  # 0.5 % of the surface per arrow key
        self.threshold_slider.setPageStep(50)
        self.t1_edit = QtWidgets.QLineEdit(placeholderText="default")
        self.t2_edit = QtWidgets.QLineEdit(placeholderText="default")
        self.pick_label = WrappingLabel("Click the surface to pick a vertex.")
        self.distance_button = QtWidgets.QPushButton(
            "Show distance", toolTip="Distance from the picked vertex (D)"
        )
        form.addRow("Kind", self.kind_combo)
        form.addRow("Display", self.display_combo)
        form.addRow("Threshold", self.threshold_slider)
        form.addRow("", self.threshold_label)
        form.addRow(self.by_share_check)
        form.addRow("t1", self.t1_edit)
        form.addRow("t2", self.t2_edit)
        self.range_label = WrappingLabel("")  # what was wrong with a typed scale range
        form.addRow(self.range_label)
        form.addRow(self.pick_label)
        form.addRow(self.distance_button)
        self.scale_slider = slider(0, 99, "Show the signature at this scale")
        form.addRow("Signature at scale", self.scale_slider)
        self.scale_edit = QtWidgets.QLineEdit(
            toolTip="Type a scale t: the signature is summed at t itself (the slider shows "
            "the nearest sample)"
        )
        for edit in (self.t1_edit, self.t2_edit, self.scale_edit):  # scales t (or energies E)
            edit.setValidator(QtGui.QDoubleValidator(0.0, 1e30, 12))
        log_tip = "Colour the signature by log10(S / smallest S)"
        self.log_check = QtWidgets.QCheckBox("Log colours", toolTip=log_tip)
        self.scale_row = row((self.scale_edit, 1), self.log_check)
        form.addRow("t", self.scale_row)
        self.signature_plot = LinePlot("Signature of the picked vertex", "t (log)", "S_t")
        form.addRow(self.signature_plot)

        self.kind_combo.currentIndexChanged.connect(self._on_kind)
        bind(self.display_combo, lambda display: state.set_display(distance_display=display))
        self.threshold_slider.valueChanged.connect(self._on_slider)
        bind(self.by_share_check, lambda on: self.state.set_display(keep_share=on))
        self.t1_edit.editingFinished.connect(self._on_range)
        self.t2_edit.editingFinished.connect(self._on_range)
        self.distance_button.clicked.connect(lambda: viewer.show_distance())
        self.scale_slider.valueChanged.connect(self._on_scale)
        self.scale_edit.editingFinished.connect(self._on_scale_typed)
        bind(self.log_check, lambda on: setattr(self.state.style, "log_signature", on))
        state.events.style.connect(
            lambda: show_values([(self.log_check, self.state.style.log_signature)])
        )
        state.events.signature_curve.connect(self._update_signature_plot)
        follow(state, self.update_from_state, "display", "pick", "spectra", "mesh", "scale_range")
        self.update_from_state()

    # ------------------------------------------------------------- input
    def _on_kind(self, _index: int) -> None:
        """Another distance kind (a threshold map keeps its share of the surface: see
        :meth:`ViewerState._match_threshold`)."""
        self.state.set_display(distance_kind=self.kind_combo.currentData())
        picked = self.state.picked is not None
        if self.state.display.kind == "distance" or (
            picked and self.state.display.kind != "signature"
        ):
            # with a vertex picked the new kind's map is shown (also after a map that
            # failed, which left the mode on screen)
            self.viewer.show_distance()
        elif self.state.display.kind == "signature":
            self.viewer.show_signature(self.state.display.signature_sample)

    def _on_slider(self, value: int) -> None:
        position = value / SLIDER_STEPS
        if self.by_share_check.isChecked():
            fraction = self.state.derived.threshold_for_share(position)
        else:
            fraction = position
        self.state.set_display(threshold=fraction)

    def _on_range(self) -> None:
        """A typed t1 or t2: an empty field keeps its default (or the value in use); a
        range that is not 0 < t1 < t2 is said below the fields and not taken."""
        texts = [self.t1_edit.text().strip(), self.t2_edit.text().strip()]
        if not any(texts):
            self.range_label.setText("")
            self.state.set_scale_range(None)
            return
        try:
            typed = [float(t) if t else None for t in texts]
        except ValueError:  # the validator lets through what it cannot finish
            self.range_label.setText("t1 and t2 are scales (positive numbers).")
            return
        defaults = self.state.derived.default_range()
        if None in typed and defaults is None:
            self.range_label.setText(
                "Type both t1 and t2, or compute the distance's spectrum first (an empty "
                "field then takes its default)."
            )
            return
        t1, t2 = (t if t is not None else d for t, d in zip(typed, defaults or typed, strict=True))
        try:
            self.state.set_scale_range((t1, t2))
        except ValueError:
            self.range_label.setText(
                f"t1 must be above 0 and below t2 (t1 = {t1:.4g}, t2 = {t2:.4g}); the "
                "range in use is kept."
            )
            return
        self.range_label.setText("")

    def _on_scale(self, value: int) -> None:
        self.state.set_display(signature_sample=value)  # kept while signatures are missing
        self.viewer.show_signature(value)

    def _on_scale_typed(self) -> None:
        """A typed scale t: the signature at t itself (not the nearest sample)."""
        try:
            t = float(self.scale_edit.text())
        except ValueError:
            return
        if t > 0:
            self.viewer.show_signature_at(t)
        else:
            self.viewer.show_signature(self.state.display.signature_sample)

    # ------------------------------------------------------------ output
    def update_from_state(self, *_args) -> None:
        state = self.state
        d = state.display
        dist = state.derived.distance_map()
        fraction = d.threshold if dist is None else state.derived.map_fraction(dist)
        if dist is not None and d.keep_share:
            position = state.derived.surface_share(dist, fraction * float(dist.max()))
        else:
            position = fraction
        show_values(
            (
                (self.by_share_check, d.keep_share),
                (self.kind_combo, d.distance_kind),
                (self.display_combo, d.distance_display),
                (self.scale_slider, d.signature_sample),
                (self.threshold_slider, max(1, int(round(position * SLIDER_STEPS)))),
            )
        )
        self.threshold_slider.setEnabled(d.distance_display == "threshold")
        if dist is not None:
            thr = fraction * float(dist.max())
            share = 100.0 * state.derived.surface_share(dist, thr)
            self.threshold_label.setText(f"< {thr:.4g} ({share:.1f} % of surface)")
        elif state.picked is not None:
            operator = operator_for_distance(d.distance_kind)
            if any(key.operator == operator for key in state.computing):
                self.threshold_label.setText("The map follows when its spectrum is computed")
            else:
                self.threshold_label.setText("Show distance (D) computes the spectrum it needs")
        elif d.keep_share:
            self.threshold_label.setText("Marks a share of the surface once a vertex is picked")
        else:
            self.threshold_label.setText(f"{d.threshold:.3g} of the largest distance")
        if state.picked is None:
            self.pick_label.setText("Click the surface to pick a vertex.")
        else:
            x, y, z = state.mesh.vertices[state.picked]
            self.pick_label.setText(
                f"Picked vertex {state.picked_file_vertex} at ({x:.4g}, {y:.4g}, {z:.4g})"
            )
        self._update_scale_words()
        self._update_scale_fields()
        self._update_signature_plot()

    def _update_scale_words(self) -> None:
        """A wave kernel's scales are energies E, the others' times t."""
        wave = self.state.derived.wave()
        form = self.layout()
        for edit, word in ((self.t1_edit, "1"), (self.t2_edit, "2"), (self.scale_row, "")):
            label = form.labelForField(edit)
            if label is not None:
                label.setText(("E" if wave else "t") + word)
        plot = self.signature_plot
        plot.xlabel, plot.ylabel = ("E (log)", "W_E") if wave else ("t (log)", "S_t")

    def _update_scale_fields(self) -> None:
        """t1 and t2 say their defaults (the kind's range), and the scale box the scale t
        the signature is (or would be) shown at."""
        derived = self.state.derived
        shown = derived.has_signatures(operator_for_distance(self.state.display.distance_kind))
        times = derived.kind_table().times[[0, -1]] if shown else (None, None)
        for edit, t in zip((self.t1_edit, self.t2_edit), times, strict=True):
            edit.setPlaceholderText("default" if t is None else f"default {t:.4g}")
            if shown and self.state.t_range is None:
                with quiet(edit):
                    edit.clear()
        if not self.scale_edit.hasFocus():
            with quiet(self.scale_edit):
                self.scale_edit.setText(f"{derived.signature_time():.4g}" if shown else "")

    def _update_signature_plot(self) -> None:
        state = self.state
        operator = operator_for_distance(state.display.distance_kind)
        curve = state.derived.curve()
        if curve is None:
            self.signature_plot.set_data([], [], title="Signature of the picked vertex")
            return
        times, values = curve
        self.signature_plot.set_data(
            times,
            values,
            logx=True,
            markers=False,
            title=(
                f"Signature of vertex {state.picked_file_vertex} "
                f"({OPERATOR_INFO[operator].short_label})"
            ),
        )
        self._show_exact_curve()

    def _show_exact_curve(self) -> None:
        """Where the truncation estimate of the curve is large, the curve summed over all
        modes (a job, off the GUI thread) dashed beside it."""
        from ...core.truncation import TRUNCATION_LEVEL

        derived = self.state.derived
        error = derived.curve_truncation()
        if error is None or error <= TRUNCATION_LEVEL:
            return
        exact = derived.exact_curve()
        if exact is None:
            self.viewer.request_exact_curve()
            return
        self.signature_plot.set_second(exact, "dashed: all modes")
