"""Voxel volumes (digital cores): selections, bit maps, bricks, octree, skip
maps and their packed layout, visibility, porosity, regions of interest,
samples, thresholds, lazy (dask) selection maps, synthetic cores."""
