"""Where a :class:`~geoshade.core.view.CoreView`'s voxels live: the *source* of its selection
maps, chosen when the View opens (:func:`open_source`):

- :class:`ArraySource`: a volume in memory (numpy, a memory-mapped file): the maps by the
  in-memory slab loop on :data:`~geoshade.scheduler.HERE` (the default), else as dask tasks on
  the View's scheduler;
- :class:`StoreSource`: a volume out of core (a dask array over a store): the maps as dask
  tasks on the View's scheduler, slab by slab.

A source reads the options' region of interest into its values (voxels outside read as a
value the selection never takes, :func:`geoshade.compute.roi.masked_data`) and builds the
selection maps of a box or a brick; every drawing (whole, bricked, cluster,
:mod:`geoshade.core.backends`) reads its voxels through it.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from geoshade.compute.bricks import is_dask, selection_maps_for
from geoshade.compute.lazy import as_dask
from geoshade.compute.roi import masked_data, outside_value
from geoshade.models.volume import Box, VoxelVolume
from geoshade.scheduler import Scheduler


@runtime_checkable
class VolumeSource(Protocol):
    """What a core drawing asks of the voxels it draws."""

    #: ``"array"`` or ``"store"``
    name: str
    volume: VoxelVolume
    #: where its work runs (the View's scheduler session; None: here)
    work: Any
    progress: Any
    #: a cluster's workers read their bricks themselves (else each is sent its bricks' values)
    workers_read: bool

    def data(self, options):
        """The values the selection is made of: the volume's, masked by the options' ROI."""

    def maps(self, options, box: Box | None = None, progress=None):
        """The selection maps of ``box`` (default the options' box) under the options'
        selection and colour range (no GL: any thread)."""

    def brick_values(self, data, brick: Box) -> np.ndarray | None:
        """The values of ``brick`` a cluster's worker is sent (None: it reads them itself)."""


def roi_fill(volume: VoxelVolume, o):
    """The value outside the ROI reads as under ``o``'s selection (None: no ROI)."""
    if o.roi is None:
        return None
    dt, fill = outside_value(volume.dtype, *o.select)
    return (dt.str, repr(fill))


def _maps(source, options, box, progress):
    lo, hi = options.select
    clo, chi = options.color_range()
    return selection_maps_for(source.data(options), options.box if box is None else box, lo,
                              hi, clo, chi, scheduler=source.work,
                              progress=progress or source.progress)


class ArraySource:
    """A volume in memory (see the module); ``work``: the View's scheduler session (None:
    here)."""

    name = "array"
    workers_read = False

    def __init__(self, volume: VoxelVolume, work=None, progress=None):
        self.volume, self.work, self.progress = volume, work, progress

    def data(self, options):
        if options.roi is None:
            return self.volume.data
        data = self.volume.data
        if not Scheduler.parse(self.work).in_place:   # dask graphs for every computation
            data = as_dask(data)
        return masked_data(data, options.roi, *options.select)

    def maps(self, options, box: Box | None = None, progress=None):
        return _maps(self, options, box, progress)

    def brick_values(self, data, brick: Box) -> np.ndarray:
        """The values of ``brick`` (a masked volume is a dask array over it: computed here,
        brick by brick)."""
        sub = data[brick.slices()]
        return np.asarray(sub.compute(scheduler="synchronous") if is_dask(sub) else sub)


class StoreSource:
    """A volume out of core (see the module)."""

    name = "store"
    workers_read = True

    def __init__(self, volume: VoxelVolume, work=None, progress=None):
        self.volume, self.work, self.progress = volume, work, progress

    def data(self, options):
        if options.roi is None:
            return self.volume.data
        return masked_data(self.volume.data, options.roi, *options.select)

    def maps(self, options, box: Box | None = None, progress=None):
        return _maps(self, options, box, progress)

    def brick_values(self, data, brick: Box) -> None:
        return None   # each worker reads its bricks from the store


def open_source(volume: VoxelVolume, work=None, progress=None) -> VolumeSource:
    """The source of ``volume``: a store (dask array) or an array in memory."""
    cls = StoreSource if is_dask(volume.data) else ArraySource
    return cls(volume, work, progress)


__all__ = ["ArraySource", "StoreSource", "VolumeSource", "open_source", "roi_fill"]
