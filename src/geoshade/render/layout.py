"""One definition for every bit layout and constant shared by Python and GLSL.

The shaders declare these names with ``#pragma geoshade define NAME``; :func:`voxel_defines`
emits their values, so a layout is never written down twice.
"""

from __future__ import annotations

import numpy as np

from geoshade.compute.voxels.skipmap import SKIP_BRICK
from geoshade.compute.voxels.visibility import trefoil_tables

#: voxels per side of a patch-quad's thread group is PATCH_L + 1 (the paper's l = 64)
PATCH_L = 64
#: bits per word of the packed voxel bit map (R32UI texel); bit x % 32 of word x // 32
BITS_PER_WORD = 32
#: side of the ray caster's skip-map bricks, in voxels (the skip map's layout needs 8)
BRICK = SKIP_BRICK
#: llvmpipe re-uses patches once one draw (or instance) tessellates more than 65,536 vertices
#: (PLATFORM.md); each instance carries at most this many patch-quads and the patch index is
#: computed as gl_InstanceID * PATCHES_PER_INSTANCE + gl_VertexID.
TESS_VERTEX_LIMIT = 65536
#: texture units
UNIT_BITS, UNIT_PATCH_BITS, UNIT_COLOR, UNIT_PALETTE, UNIT_BRICKS = 0, 1, 2, 3, 4
#: shader storage binding of the ray caster's "seen voxels" bit set (count pass only)
SSBO_COUNT = 0
#: trefoil selection: 0 = per voxel from the eye position (exact under perspective and with the
#: camera inside the box), 1 = the paper's Eq. (1), one trefoil per frame from the normal matrix
TREFOIL_EYE, TREFOIL_PAPER = 0, 1


def patches_per_instance(level: int = PATCH_L, software: bool = True) -> int:
    """Patch-quads per instance so that one instance tessellates <= 65,536 vertices.

    On hardware drivers the bug does not exist, but the same code path with bigger instances is
    used so that both paths are the same program.
    """
    per_patch = (level + 1) ** 2
    if software:
        return max(1, TESS_VERTEX_LIMIT // per_patch)
    return 1024


def _glsl_int_array(a) -> str:
    a = np.asarray(a).ravel()
    return f"int[{a.size}](" + ",".join(str(int(v)) for v in a) + ")"


def voxel_defines() -> dict:
    """GLSL ``#define`` values for the voxel visuals (bit map layout, trefoil tables)."""
    S, N = trefoil_tables()
    return {
        "PATCH_L": PATCH_L,
        "BITS_PER_WORD": BITS_PER_WORD,
        "BRICK": BRICK,
        "UNIT_BITS": UNIT_BITS,
        "UNIT_PATCH_BITS": UNIT_PATCH_BITS,
        "UNIT_COLOR": UNIT_COLOR,
        "UNIT_PALETTE": UNIT_PALETTE,
        "UNIT_BRICKS": UNIT_BRICKS,
        "TREFOIL_S": _glsl_int_array(S),
        "TREFOIL_N": _glsl_int_array(np.maximum(N, 0)),
    }
