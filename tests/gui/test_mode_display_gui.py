"""The window's controls of how 3D modes and colour ranges are drawn."""

from modalviewer.gui import menus


def test_ghost_and_colour_range_follow_the_state(window, spot_path):
    assert window.open_mesh(spot_path)
    state = window.state
    box = window.modes_panel.color_combo
    assert box.currentData() == "deformed" and box.currentText() == "Deformed shape"
    box.setCurrentIndex(box.findData("normal"))
    assert state.style.shell_coloring == "normal"
    assert window.ghost_action.shortcut().toString() == "G"
    window.ghost_action.trigger()
    assert state.style.ghost is False
    state.style.ghost = True
    assert window.ghost_action.isChecked()
    actions = window.color_range_actions
    assert actions["auto"].isChecked()
    actions["robust"].trigger()
    assert state.style.color_range == "robust"
    state.set_color_range("limits", (0.0, 2.0))
    assert actions["limits"].isChecked()
    assert "G " in menus.CONTROLS
