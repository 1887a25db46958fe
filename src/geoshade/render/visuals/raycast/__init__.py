"""The ``raycast`` voxel method: an exact voxel ray caster (3D DDA over the bit map).

See :class:`geoshade.render.visuals.raycast.visual.RaycastVisual`.
"""
