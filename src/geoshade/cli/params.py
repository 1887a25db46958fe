"""``--param FILE`` (repeatable) on the commands that open a corner-point grid: ROFF parameter
files and GRDECL property files added to the grid's properties (a ``load`` hint,
:mod:`geoshade.io.grids.params`)."""

from __future__ import annotations

import argparse


def add_param_arg(p: argparse.ArgumentParser) -> None:
    """``--param FILE`` (repeatable)."""
    p.add_argument("--param", metavar="FILE", action="append", default=None,
                   help="a property file for the grid (repeat for several): a ROFF parameter "
                        "file (.roff, any name; RMS's GRID--name.roff beside a ROFF grid are "
                        "read anyway) or a GRDECL file of PORO/PERMX/... keywords with one "
                        "value a cell; its properties join the grid's (same name: replaced)")


def param_hint(args) -> dict:
    """``{"params": [...]}`` when ``--param`` was given (a load hint), else {}."""
    files = getattr(args, "param", None)
    return {"params": list(files)} if files else {}


__all__ = ["add_param_arg", "param_hint"]
