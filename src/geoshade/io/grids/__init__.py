"""Corner-point grids and decks: GRDECL, ECLIPSE/OPM binary and formatted files, ROFF, wells."""
