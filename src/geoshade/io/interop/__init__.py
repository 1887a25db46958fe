"""Models to and from other libraries: PyVista, xarray, mesh files.

The models' ``to_pyvista()``/``to_xarray()`` methods reach :mod:`.pyvista_io` and
:mod:`.xarray_io` by name (:data:`geoshade.models.convert.CONVERTERS`): nothing registers them at
import.
"""
