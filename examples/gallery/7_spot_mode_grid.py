"""A row of modes
================

The paper's figures put modes side by side.  ``export_mode_grid`` draws modes 6 to 13
of spot's 3D vibrations in one picture: one camera fitted to all the deformed shapes,
each panel captioned with its mode number and eigenvalue, every panel coloured over one
range and one colour bar below (``modalviewer render MESH --operator shells --modes
6-13 --grid 4x2 -o row.png`` from the command line).
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("spot.obj"))
viewer.compute("shells", k=20)
viewer.export_mode_grid("spot_modes.png", range(6, 14), grid=(4, 2), size=(300, 260))
viewer.close()
