"""Drawing the viewer's state with VTK/PyVista, no Qt: one code path on screen (the Qt
windows embed the same classes) and off screen."""
