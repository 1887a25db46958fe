"""Models to and from other libraries: PyVista, xarray, mesh files."""
