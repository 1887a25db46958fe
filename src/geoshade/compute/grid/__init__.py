"""Corner-point grids: visible faces, filters, geometry, chunks, coarse levels,
cell values, synthetic grids."""
