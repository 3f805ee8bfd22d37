"""A vibration mode of a closed shell
===================================

The Discrete Shells Hessian at rest gives vibration modes that move the surface in 3D,
not just a scalar per vertex.  Mode 8 of the cow ``spot.obj`` (2930 vertices, 20 modes)
is drawn as the viewer draws 3D modes: the surface displaced by the mode, coloured by
the length of the displacement, over a faint ghost of the rest shape.  The animation
is one period of the mode vibrating as the window shows it (``export_animation``: a GIF,
or an MP4 where imageio-ffmpeg is installed).
"""

import modalviewer as mv

viewer = mv.Viewer()
viewer.open_mesh(mv.asset_path("spot.obj"))
viewer.compute("shells", k=20)
viewer.show_mode(8)  # 3D modes are shown deformed, over the rest shape's ghost
viewer.export_screenshot("spot_vibration_mode.png", size=(800, 600))
viewer.export_animation("spot_vibration_mode.gif", size=(480, 360))
viewer.close()
