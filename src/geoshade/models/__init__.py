"""Plain numpy-backed data classes with explicit shape and dtype contracts (no GL, no file IO)."""

from geoshade.models.field import FieldSeries, TriangleMesh
from geoshade.models.grid import CornerPointGrid, Fault, WellPath
from geoshade.models.stacks import BoreholeLogs, Legend, StackModel
from geoshade.models.volume import Box, VoxelVolume

__all__ = ["Box", "CornerPointGrid", "Fault", "FieldSeries", "TriangleMesh", "VoxelVolume",
           "WellPath"]
__all__ += ["BoreholeLogs", "Legend", "StackModel"]  # stacks part
