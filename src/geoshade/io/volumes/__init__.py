"""Voxel volumes: raw (+ NRRD/MetaImage headers), TIFF, npy/npz, image stacks, HDF5."""
