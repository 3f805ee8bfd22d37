"""The status line counts grammatically ("1 face", not "1 faces")."""

import numpy as np

from modalviewer.core.mesh import Mesh
from modalviewer.viewer import wording
from modalviewer.viewer.state import ViewerState


def test_a_one_triangle_mesh_reads_one_face():
    state = ViewerState()
    state.set_mesh(Mesh(np.eye(3), np.array([[0, 1, 2]])))
    text = wording.summary(state)
    assert text.startswith("3 vertices, 1 face") and "1 faces" not in text
