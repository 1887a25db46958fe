"""napari plugin (npe2): napari opens the volumes geoshade reads, and saves labels for geoshade.

An adapter, like :mod:`geoshade.cli` and :mod:`geoshade.viewer`: it only calls geoshade's public
API.  napari is optional (``pip install 'geoshade[napari]'``); nothing here imports it at import
time.  The manifest ``napari.yaml`` (entry point ``napari.manifest``) contributes:

- a **reader** for zarr stores (geoshade's ingest stores and any OME-Zarr image: one multiscale
  image layer of all the levels), TIFF stacks and folders of TIFF slices, ``.npy``/``.npz``,
  HDF5 (one 3D dataset), and the other self-describing formats :func:`geoshade.load` reads
  (raw files need hints napari cannot give): ``scale`` from the spacing (z, y, x), ``translate``
  from the origin, ``metadata`` with the unit and the source (:func:`layer_data`);
- a **writer** for labels layers: a geoshade zarr store keeping spacing, origin and unit
  (:func:`write_labels`);
- a **widget** generated from :func:`selection_widget`: geoshade's core selection (the values in
  ``[lo, hi]``) of an image layer as a labels layer (:func:`selection_labels` in Python).

Examples
--------
>>> import numpy as np
>>> from geoshade.models import VoxelVolume
>>> data, kw, kind = selection_labels(VoxelVolume(np.arange(8, dtype=np.uint8).reshape(2, 2, 2)),
...                                   2, 5)
>>> int(data.sum()), kind
(4, 'labels')
"""

from __future__ import annotations

from geoshade.napari._labels import selection_labels, selection_widget, write_labels
from geoshade.napari._reader import get_reader, layer_data, layer_kwargs, read_layers

__all__ = ["get_reader", "layer_data", "layer_kwargs", "read_layers", "selection_labels",
           "selection_widget", "write_labels"]
