"""Where the surface vibrates alike: a threshold map
=================================================

The vibration distance compares how two points move in the low vibration modes, over
all time scales.  Picking vertex 2000 on spot's far flank (out of view, with its
marker) and marking the tenth of the surface's area closest to it (``share=0.1``) finds
the matching region on the near flank, shown here, and the regions that vibrate in the
same way.  100 modes; the first call computes the
spectrum, the map is drawn once it is in.
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("spot.obj"))
viewer.compute("shells", k=100)
viewer.pick_vertex(2000)
distances = viewer.show_distance("vibration", display="threshold", share=0.1)
print(f"vibration distance from vertex 2000: 0 to {distances.max():.3g}")
viewer.export_screenshot("spot_vibration_threshold.png", size=(800, 600))
viewer.close()
