"""Wave and heat kernel distances on spot
=======================================

Both signatures come from the Laplacian's modes.  The heat kernel signature weighs them
by ``exp(-lambda t)``, a low-pass filter, so at every scale the lowest modes weigh most;
the wave kernel signature (Aubry, Schlickewei, Cremers 2011) weighs them by a Gaussian in
``log lambda``, a band-pass filter, so each energy sees its own band of modes.  From
vertex 2000 on spot's far flank (out of view), the tenth of the surface's area closest by
each distance (blue): the wave kernel marks a band across the middle of the near flank,
the heat kernel the near flank's rear and a strip of the neck.  100 modes.
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("spot.obj"))
viewer.compute("laplacian", k=100)
viewer.pick_vertex(2000)
for kind in ("wks", "hks"):
    d = viewer.show_distance(kind, display="threshold", share=0.1)
    print(f"{kind}: distances from vertex 2000 up to {d.max():.3g}")
compare = viewer.comparison(["wks", "hks"])
viewer.export_comparison(compare, "spot_wks_vs_hks.png", size=(560, 480))
viewer.close()
