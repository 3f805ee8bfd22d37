"""Laplacian and E_D^N modes of a folded plate
============================================

The paper's Fig. 1: the same mode index of the cotan Laplacian and of the modified
Dirichlet energy E_D^N on a plate folded along a line.  The Laplacian sees only the
intrinsic geometry, so its modes run across the fold as if the plate were flat; E_D^N
measures how the surface bends, and its modes follow the fold.  Each spectrum has a
dozen modes (1225 vertices); the two views are drawn side by side with ten isolines.
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("demo_folded_plate.obj"))
viewer.state.style.isolines = 10
viewer.compute("laplacian", k=12)
viewer.compute("modified_dirichlet", k=12)
compare = viewer.comparison(["laplacian", "modified_dirichlet"])
compare.show_mode(5)
viewer.export_comparison(compare, "folded_plate_modes.png", size=(560, 480))
viewer.close()
