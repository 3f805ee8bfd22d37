"""Drawing the viewer's state with VTK/PyVista: one code path on screen and off screen.

No Qt here.  :class:`~.mesh_scene.MeshScene` owns one mesh's actors on any pyvista
plotter; :class:`~.view.StateScene` keeps one in step with a
:class:`~modalviewer.viewer.state.ViewerState`; :class:`~.offscreen.OffscreenRenderer`
puts one off screen.  The Qt windows embed the same classes.
"""
