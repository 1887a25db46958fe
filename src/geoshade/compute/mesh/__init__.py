"""Isosurfaces: the marching-cubes tables and CPU reference, synthetic fields
over time."""
