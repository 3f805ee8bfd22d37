"""Heat kernel and vibration distance on a bent hand
=================================================

The heat kernel distance (from the Laplacian) depends only on the intrinsic geometry,
which bending a finger does not change; the vibration distance (from the Discrete Shells)
also sees how the surface is bent.  From the ring fingertip of the bent hand (a landmark
of ``demo_landmarks.json``), the heat kernel marks the bent middle fingertip as similar;
the vibration distance leaves it out and marks the straight index fingertip.  Both maps
mark the 5 % of the area closest to the pick; 50 modes each.
"""

import json

import modalviewer as mv

landmarks = json.loads(mv.asset_path("demo_landmarks.json").read_text())["demo_hand_bent"]

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("demo_hand_bent.obj"))
viewer.compute("shells", k=50)
viewer.compute("laplacian", k=50)
viewer.pick_vertex(landmarks["finger2"])
viewer.show_distance("vibration", display="threshold", share=0.05)
compare = viewer.comparison(["vibration", "hks"])
viewer.export_comparison(compare, "hand_vibration_vs_hks.png", size=(560, 480))
viewer.close()
