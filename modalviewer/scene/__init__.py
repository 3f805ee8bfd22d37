"""Drawing the viewer's state with VTK/PyVista: one code path on screen and off screen.

No Qt here.  :class:`~.mesh_scene.MeshScene` owns the actors of one mesh on any pyvista
plotter; :class:`~.view.StateScene` keeps one in step with a
:class:`~modalviewer.viewer.state.ViewerState`; :class:`~.offscreen.OffscreenRenderer`
puts one on an off-screen plotter for exports, the command line and notebooks.  The Qt
windows embed the same classes in their views.
"""
