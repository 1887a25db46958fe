"""What the interactive commands open and how: one definition for ``geoshade view`` and
``geoshade serve``.

Both commands take the same input options, defined here once: ``--demo`` (every part's
synthetic data), the part to open with
(``--as``), the reader hints of headerless raw volumes (``--shape --dtype --endian --spacing
--unit``), of decks (``--skip-missing``), of grids (``--param``) and of fields over time
(``--keyword``); and every drawing option of every part, generated from the options'
declarations (:mod:`geoshade.cli.options`), so ``view CASE --edges quad`` opens what
``grid render CASE --edges quad`` draws. :func:`open_hints` and :func:`open_settings` turn the
parsed arguments into :func:`geoshade.load` hints and View options.

>>> import argparse
>>> p = argparse.ArgumentParser(); add_open_args(p)
>>> a = p.parse_args(["--shape", "4", "4", "2", "--dtype", "uint8", "--property", "PORO",
...                   "--edges"])
>>> open_hints(a)
(None, {'shape': (4, 4, 2), 'dtype': 'uint8', 'endian': 'little'})
>>> open_settings(a)
{'property': 'PORO', 'edges': 'quad'}
"""

from __future__ import annotations

import argparse
import warnings

from geoshade.api import KINDS, view_class
from geoshade.cli.main import add_volume_args, volume_hints
from geoshade.cli.options import add_option_args, flag_error, typed_options
from geoshade.cli.params import add_param_arg, param_hint
from geoshade.cli.render import add_skip_missing_arg, skip_missing_hint
from geoshade.errors import InputError
from geoshade.grid.options import read_well_files
from geoshade.scheduler import Scheduler


def add_open_args(p: argparse.ArgumentParser, size: str = "900x650") -> None:
    """The input options of ``view`` and ``serve``, and every drawing option of the four parts
    (generated from their declarations, as ``<part> render`` takes them).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser (its ``PATH`` arguments are its own).
    size : str
        The picture size until the window or page says its own.
    """
    g = p.add_argument_group("input")
    g.add_argument("--demo", nargs="?", const=True, default=False, metavar="PART",
                   help="the built-in synthetic data of every part, no file needed (PART "
                        f"first: {', '.join(KINDS)})")
    g.add_argument("--as", dest="kind", choices=KINDS,
                   help="the part to open with (iso: a field over time, via load_field)")
    g.add_argument("--keyword", help="iso: array/variable/restart keyword to read (SWAT)")
    add_volume_args(g)
    add_skip_missing_arg(g)
    add_param_arg(g)
    add_option_args(p, {k: view_class(k).Options for k in KINDS}, defaults={"size": size})


def open_hints(args) -> tuple[str | None, dict]:
    """The part to open with and the :func:`geoshade.load` hints.

    ``--keyword`` reads fields over time, so it makes the part ``iso`` (and is refused with
    another ``--as``); ``--skip-missing`` is refused for fields over time.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed with :func:`add_open_args`.

    Returns
    -------
    kind : str or None
    hints : dict
    """
    kind = args.kind
    hints = {**volume_hints(args), **skip_missing_hint(args), **param_hint(args)}
    if args.keyword:
        if kind not in (None, "iso"):
            raise InputError("--keyword: applies to fields over time (--as iso)")
        kind = "iso"
        hints["keyword"] = args.keyword
    if args.skip_missing and kind == "iso":  # fields over time do not read INCLUDEs
        raise InputError("--skip-missing: applies to decks and GRDECL files opened as grids")
    return kind, hints


def open_settings(args) -> dict:
    """The View options typed on the command line (only those given; a part that does not take
    one refuses it in one line when it opens), their values checked as far as they can be
    without the model.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed with :func:`add_open_args`.

    Returns
    -------
    dict
        ``{option: value}``.
    """
    s = typed_options(args)
    if s.get("distributed") and not s.get("scheduler"):
        raise InputError("--distributed: give the cluster with --scheduler ADDRESS "
                         "(tcp://HOST:8786) or --scheduler local:N")
    if "scheduler" in s:
        s["scheduler"] = Scheduler.parse(s["scheduler"])   # refused before opening anything
    for key, value in s.items():   # each value's syntax, before opening: some part takes it
        if key in ("wells", "scheduler"):
            continue
        errors = []
        for kind in KINDS:
            cls = view_class(kind).Options
            if key not in set(cls.names()) | set(cls.DEPRECATED):
                continue
            with warnings.catch_warnings():   # a deprecated name warns once, when it opens
                warnings.simplefilter("ignore")
                try:
                    cls.parse(None, **{key: value},   # --distributed is checked with its cluster
                              **({"scheduler": s["scheduler"]} if key == "distributed" else {}))
                    break
                except InputError as err:
                    errors.append(err)
        else:
            if errors:
                raise flag_error(errors[0], args)
    if "wells" in s:   # read once here, shared by every View opened
        s["wells"] = [w for f in s["wells"] for w in read_well_files(f)]
    return s


__all__ = ["add_open_args", "open_hints", "open_settings"]
