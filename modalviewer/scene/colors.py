"""The colours of the pictures: the paper's palette, the colour maps' lookup tables and
the rendering styles."""

from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.util.numpy_support import numpy_to_vtk

# The paper's colours: blue positive, white zero, orange negative.
BLUE = np.array([0.16, 0.38, 0.78])
WHITE = np.array([1.0, 1.0, 1.0])
ORANGE = np.array([0.96, 0.55, 0.12])
RED = np.array([0.78, 0.08, 0.08])
SIMILAR_BLUE = np.array([0.20, 0.45, 0.85])


def lookup_table(colors: list[np.ndarray], n: int = 256) -> pv.LookupTable:
    """A lookup table interpolating linearly through ``colors`` (RGB in [0, 1])."""
    anchors = np.linspace(0.0, 1.0, len(colors))
    x = np.linspace(0.0, 1.0, n)
    rgb = np.column_stack([np.interp(x, anchors, [c[i] for c in colors]) for i in range(3)])
    return _table(rgb)


def _table(rgb: np.ndarray) -> pv.LookupTable:
    """A lookup table of the (n, 3) colours ``rgb`` in [0, 1], opaque."""
    table = np.column_stack([rgb, np.ones(len(rgb))])
    lut = pv.LookupTable()
    lut.SetNumberOfTableValues(len(rgb))
    lut.SetTable(numpy_to_vtk((255 * table).round().astype(np.uint8), deep=True))
    return lut


# Rendering styles.  "paper": one headlight (view-locked shading, as Polyscope's matcap
# gives, with VTK's own lighting on and off screen) over a high ambient term, so
# min(1, ambient + diffuse * cos) keeps white white and colours saturated where the
# surface faces the viewer and falls to 0.3 toward silhouettes; no specular term (a
# highlight would wash the colours out).  "shaded": pyvista's light kit with plain
# diffuse shading: more relief, darker colours.
STYLES = {
    "paper": {"ambient": 0.3, "diffuse": 0.9, "specular": 0.0, "lights": "headlight"},
    "shaded": {"ambient": 0.0, "diffuse": 1.0, "specular": 0.0, "lights": "light kit"},
}
DEFAULT_STYLE = "paper"
COLORMAPS = {  # colours from the low to the high end of each colour map
    "diverging": [ORANGE, WHITE, BLUE],
    "sequential": [WHITE, RED],
    "plain": [WHITE, RED],
    "threshold": [SIMILAR_BLUE, WHITE],
}
DIVERGING = lookup_table([ORANGE, WHITE, BLUE])  # negative -> zero -> positive
SEQUENTIAL = lookup_table([WHITE, RED])  # similar -> dissimilar
# closer than the threshold -> blue: 2048 entries, so that the step of
# MeshScene.show_threshold, which looks colours up after interpolation along the surface,
# falls within 1/2048 of the range from the threshold
THRESHOLD = _table(np.where(np.arange(2048)[:, None] < 1024, SIMILAR_BLUE, WHITE))
