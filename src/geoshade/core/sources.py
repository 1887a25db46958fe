"""Where a :class:`~geoshade.core.view.CoreView`'s voxels live: the *source* of its selection
maps (:class:`VolumeSource`), chosen when the View opens (:func:`open_source`):

- ``"array"``: a volume in memory (numpy, a memory-mapped file): the maps by the in-memory
  slab loop on :data:`~geoshade.scheduler.HERE` (the default), else as dask tasks on the View's
  scheduler; a cluster's workers are sent their bricks' values;
- ``"store"``: a volume out of core (a dask array over a store): the maps as dask tasks on the
  View's scheduler, slab by slab; a cluster's workers read their bricks themselves.

A source reads the options' region of interest into its values (voxels outside read as a
value the selection never takes, :func:`geoshade.compute.voxels.roi.masked_data`) and builds the
selection maps of a box or a brick; every drawing (whole, bricked, cluster,
:mod:`geoshade.core.backends`) reads its voxels through it and asks what it supports
(``workers_read``), never its type.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geoshade.compute.voxels.bricks import is_dask, selection_maps_for
from geoshade.compute.voxels.lazy import as_dask
from geoshade.compute.voxels.roi import masked_data, outside_value
from geoshade.models.volume import Box, VoxelVolume
from geoshade.scheduler import Scheduler, dask_get


def roi_fill(volume: VoxelVolume, o):
    """The value outside the ROI reads as under ``o``'s selection (None: no ROI)."""
    if o.roi is None:
        return None
    dt, fill = outside_value(volume.dtype, *o.select)
    return (dt.str, repr(fill))


class VolumeSource:
    """The voxels of ``volume`` (see the module); ``work``: the View's scheduler session (None:
    here), ``progress``: its callback.

    Examples
    --------
    >>> from geoshade.compute.voxels.synthetic import synthetic_core
    >>> from geoshade.core.options import CoreOptions
    >>> vol = synthetic_core(16)
    >>> src = open_source(vol)
    >>> src.name, src.workers_read, src.maps(CoreOptions.parse(vol, select=(0, 9000))).count > 0
    ('array', False, True)
    """

    def __init__(self, volume: VoxelVolume, work=None, progress=None):
        self.volume, self.work, self.progress = volume, work, progress
        #: ``"array"`` (in memory) or ``"store"`` (a dask array)
        self.name = "store" if is_dask(volume.data) else "array"
        #: a cluster's workers read their bricks themselves (else each is sent its values)
        self.workers_read: bool = self.name == "store"

    def data(self, options):
        """The values the selection is made of: the volume's, masked by the options' ROI
        (evaluated per slab, chunk or brick; a dask array unless computed here)."""
        if options.roi is None:
            return self.volume.data
        data = self.volume.data
        if not Scheduler.parse(self.work).in_place:   # dask graphs for every computation
            data = as_dask(data)
        return masked_data(data, options.roi, *options.select)

    def maps(self, options, box: Box | None = None, progress=None):
        """The selection maps of ``box`` (default the options' box) under the options'
        selection and colour range (no GL: any thread)."""
        lo, hi = options.select
        clo, chi = options.color_range()
        return selection_maps_for(self.data(options), options.box if box is None else box, lo,
                                  hi, clo, chi, scheduler=self.work,
                                  progress=progress or self.progress)

    def brick_values(self, data, brick: Box) -> np.ndarray | None:
        """The values of ``brick`` of ``data`` (:meth:`data`) a cluster's worker is sent; None
        where the workers read them (a masked array is a dask array over it: computed here,
        brick by brick)."""
        if self.workers_read:
            return None
        sub = data[brick.slices()]
        return np.asarray(sub.compute(scheduler=dask_get("synchronous")) if is_dask(sub) else sub)


def open_source(volume: VoxelVolume, work: Any = None, progress=None) -> VolumeSource:
    """The source of ``volume``: an array in memory or a store (a dask array)."""
    return VolumeSource(volume, work, progress)


__all__ = ["VolumeSource", "open_source", "roi_fill"]
