"""Animation panel: play / pause, amplitude and speed of the mode's vibration."""

from __future__ import annotations

from qtpy import QtWidgets

from ...viewer.state import ViewerState
from .common import bind, follow, row, show_values, slider


class AnimationPanel(QtWidgets.QWidget):
    """Sets ``state.animation``; only a mode on screen can play."""

    def __init__(self, state: ViewerState, parent=None):
        super().__init__(parent)
        self.state = state
        form = QtWidgets.QFormLayout(self)
        self.play_button = QtWidgets.QPushButton(
            "Play", checkable=True, toolTip="Animate the mode (Space)"
        )
        self.amp_slider = slider(
            0,
            100,
            "Largest displacement of the deformed shape and the animation: percent of a "
            "quarter of the bounding-box diagonal (40: a tenth of the diagonal)",
        )
        self.speed_slider = slider(1, 100, "Speed of the animation")
        form.addRow("Amplitude", self.amp_slider)
        # Speed and Play share a row: the Modes dock shows the whole panel at the
        # default window size, under the spectrum plot
        form.addRow("Speed", row((self.speed_slider, 1), self.play_button))
        self.fields = {
            "playing": self.play_button,
            "amplitude": self.amp_slider,
            "speed": self.speed_slider,
        }
        for name, widget in self.fields.items():
            bind(widget, lambda value, n=name: setattr(state.animation, n, value))
        follow(state, self.update_from_state, "animation", "display", "mesh")
        self.update_from_state()

    def update_from_state(self) -> None:
        anim = self.state.animation
        show_values((widget, getattr(anim, name)) for name, widget in self.fields.items())
        self.play_button.setText("Pause" if anim.playing else "Play")
        self.play_button.setEnabled(self.state.display.kind == "mode")
