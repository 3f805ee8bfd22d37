"""The feature signature of a machined part
=========================================

The feature signature is made from the E_D^N modes.  E_D^N does not penalise bending
along sharp edges and corners, so its low modes vary there freely, and the signature is
near zero on the sharp features and large on the smooth parts between them, at a scale
set by the sample index (small samples: fine detail; large: coarse regions).  Here the
machined part (4150 vertices, 100 modes) at a small scale, beside its total curvature,
which marks the same edges, but also every fillet and rounded corner.
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("demo_machined_part.obj"))
viewer.compute("modified_dirichlet", k=100)
viewer.state.set_display(distance_kind="feature")
viewer.show_signature(10)
viewer.export_screenshot("machined_part_feature_signature.png", size=(800, 600))
viewer.show_curvature()
viewer.export_screenshot("machined_part_curvature.png", size=(800, 600))
viewer.close()
