"""Layered models and terrain: GeoTOP netCDF, stack files, DEMs and drapes."""
