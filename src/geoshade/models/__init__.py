"""Plain numpy-backed data classes with explicit shape and dtype contracts (no GL, no file IO)."""

from geoshade.models.grid import CornerPointGrid, Fault, WellPath
from geoshade.models.volume import Box, VoxelVolume

__all__ = ["Box", "CornerPointGrid", "Fault", "VoxelVolume", "WellPath"]
