"""Pure array-in/array-out computations (numpy): the CPU side and references of every GPU method.

- :mod:`~geoshade.compute.voxels.selection`  value ranges, selection masks, z-slab streaming
- :mod:`~geoshade.compute.voxels.bitmaps`    bit maps, patch and brick maps, colour index map, GPU
  bytes
- :mod:`~geoshade.compute.voxels.visibility` hidden-voxel cull references, trefoil tables
- :mod:`~geoshade.compute.voxels.porosity`   porosity and its profile, CSV/JSON output
- :mod:`~geoshade.compute.voxels.synthetic`  deterministic synthetic volumes
"""

from geoshade.compute.voxels.bitmaps import (
    SelectionMaps,
    brick_occupancy,
    brick_occupancy_from_bits,
    build_selection_maps,
    color_index,
    gpu_bytes_breakdown,
    gpu_bytes_estimate,
    pack_bits,
    patch_bitmap,
    patch_grid,
    unpack_bits,
)
from geoshade.compute.voxels.porosity import PorosityResult, csv_text, porosity
from geoshade.compute.voxels.selection import check_range, select
from geoshade.compute.voxels.synthetic import random_labels, synthetic_core
from geoshade.compute.voxels.visibility import (
    exposed_mask,
    paper_normal_tables,
    trefoil_tables,
    visible_mask,
)

__all__ = [
    "PorosityResult",
    "SelectionMaps",
    "brick_occupancy",
    "brick_occupancy_from_bits",
    "build_selection_maps",
    "check_range",
    "color_index",
    "csv_text",
    "exposed_mask",
    "gpu_bytes_breakdown",
    "gpu_bytes_estimate",
    "pack_bits",
    "paper_normal_tables",
    "patch_bitmap",
    "patch_grid",
    "porosity",
    "random_labels",
    "select",
    "synthetic_core",
    "trefoil_tables",
    "unpack_bits",
    "visible_mask",
]
