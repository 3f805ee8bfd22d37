"""The best match of a point on another shape
===========================================

``viewer.pair(other)`` compares two meshes: a vertex picked on A gets a distance to every
vertex of B, from the signatures of both spectra (both meshes rescaled to unit area).
The middle fingertip of the straight hand (A) finds its best match on the tip of the
bent middle finger of B: the heat kernel distance, white near the pick's signature and
red far from it, sees through the bend.  50 Laplacian modes per mesh; the picture is
drawn by ``modalviewer.cross_figure`` with the viewer's scene and colours.
"""

import json

import modalviewer as mv
from modalviewer.cross_figure import Panel, render_panels

landmarks = json.loads(mv.asset_path("demo_landmarks.json").read_text())

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("demo_hand.obj"))
viewer.state.set_display(distance_kind="hks")
pair = viewer.pair(mv.asset_path("demo_hand_bent.obj"), k=50)
pick = landmarks["demo_hand"]["finger1"]
pair.pick("a", pick)
side, match, distance = pair.best_match()
print(f"best match on B: vertex {match}, heat kernel distance {distance:.3g}")
panels = [
    Panel(pair.mesh("a"), "A: the picked fingertip", marker=pick, azimuth=150, elevation=30),
    Panel(pair.mesh("b"), "B: heat kernel distance and best match", marker=match,
          distances=pair.distance_on("b"), azimuth=150, elevation=30,
          colorbar="heat kernel distance"),
]  # fmt: skip
render_panels(panels, "two_hands_best_match.png", size=(560, 480))
viewer.close()
