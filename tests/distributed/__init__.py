"""Distributed rendering: compositing (no GL) and pictures from a local dask cluster (gl)."""
