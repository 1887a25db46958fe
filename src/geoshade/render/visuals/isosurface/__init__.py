"""Tessellation marching cubes (the iso part's paper): isosurfaces rebuilt on the GPU each frame.

See :class:`geoshade.render.visuals.isosurface.visual.IsoSurfaceVisual`.
"""
