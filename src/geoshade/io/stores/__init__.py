"""Chunked stores: zarr/OME-Zarr volumes, grid stores, ingest with locks, checksums and atomic
publish."""
