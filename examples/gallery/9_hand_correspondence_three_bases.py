"""Matching two poses of a hand with three bases
==============================================

A functional map (``mv.functional_map``) matches shapes through their modes: descriptors
(here the heat kernel signature of each spectrum) pick the map between the two bases, and
each vertex of the bent hand is sent to the vertex of the straight one with the nearest
mapped mode values.  The bent hand is the straight one turned by 40 degrees across the
palm (``bent_pose``), vertex for vertex, so the true map is the identity and the error of
each vertex is the geodesic distance (along the edges, over the square root of the area)
between its match and itself, here at every 20th vertex.  The bases: the Laplacian, E_D^N
and the normal Discrete Shells, 30 modes each.  The pictures colour the bent hand by the
height of its match on the straight hand: where the colours jump, the map is wrong.
"""

import numpy as np

import modalviewer as mv
from modalviewer.core.demo_shapes import bent_pose

hand = mv.load_mesh(mv.asset_path("demo_hand.obj"))
bent = bent_pose(hand, 40.0)
viewer = mv.Viewer()
viewer.set_mesh(bent)
for operator in ("laplacian", "modified_dirichlet", "shells_normal"):
    sa = mv.compute_spectrum(hand, operator, k=30)
    sb = mv.compute_spectrum(bent, operator, k=30)
    fm = mv.functional_map(sa, sb, "hks", k=30)
    errors = mv.correspondence_errors(hand, fm.point_map, every=20)
    print(f"{operator}: mean geodesic error {np.nanmean(errors):.3f} sqrt(area)")
    viewer.show_field(f"height of the match ({operator})", hand.vertices[fm.point_map, 1])
    viewer.export_screenshot(f"bent_hand_{operator}.png", size=(420, 420))
viewer.close()
