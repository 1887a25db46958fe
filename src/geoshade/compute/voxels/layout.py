"""Sizes of the packed GPU layouts that several compute modules share.

The voxel bit map (:mod:`geoshade.compute.voxels.bitmaps`) packs a row of ``nx`` voxels into
:func:`words_per_row` 32-bit words; the ray caster's skip map
(:mod:`geoshade.compute.voxels.skipmap`)
has one texel of :data:`SKIP_WORDS` words per :data:`SKIP_BRICK`³ brick.  Both modules import
these from here (neither imports the other for them), and so does the GPU byte count.
"""

from __future__ import annotations

import numpy as np

#: voxels per side of a skip-map brick (the mask layout holds 4³ blocks of 2³ voxels)
SKIP_BRICK = 8
#: 32-bit words per skip-map brick texel
SKIP_WORDS = 3


def words_per_row(nx: int) -> int:
    """Number of 32-bit words holding ``nx`` bits: ``ceil(nx / 32)``.

    Examples
    --------
    >>> words_per_row(33)
    2
    """
    return -(-int(nx) // 32)


def skip_shape(shape_xyz) -> tuple[int, int, int]:
    """Skip-map bricks per axis ``(nbz, nby, nbx)`` of a box ``(nx, ny, nz)``.

    Examples
    --------
    >>> skip_shape((17, 8, 9))
    (2, 1, 3)
    """
    nx, ny, nz = (int(n) for n in shape_xyz)
    return tuple(-(-n // SKIP_BRICK) for n in (nz, ny, nx))


def skip_map_bytes(shape_xyz) -> int:
    """GPU bytes of the skip map of a box (12 bytes per 8³ brick).

    Examples
    --------
    >>> skip_map_bytes((100, 100, 100))
    26364
    """
    return SKIP_WORDS * 4 * int(np.prod(skip_shape(shape_xyz)))
