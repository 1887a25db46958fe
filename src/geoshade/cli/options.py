"""Command-line flags made from the options' declarations (:mod:`geoshade.styles.declare`).

``<part> render``, ``view`` and ``serve`` take every drawing option of a part as a flag; none is
written by hand. :func:`add_option_args` adds the flags of one options class (``render``) or of
all four parts (``view``, ``serve``: a flag two parts share is one flag, its help naming the
parts); :func:`given_options` turns what was typed into the part's options, by name, only those
given (every default is the options class's, the same for every front end). The checks of the
values are the options' own, so a bad value gives the same line everywhere.

>>> import argparse
>>> from geoshade.grid.options import GridOptions
>>> p = argparse.ArgumentParser()
>>> add_option_args(p, {"grid": GridOptions})
>>> given_options(p.parse_args(["--edges", "--faults", "hide", "--no-cull"]), GridOptions)
{'faults': 'hide', 'edges': 'quad', 'cull': False}
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from typing import Any

from geoshade.cli.main import finite_float
from geoshade.errors import InputError
from geoshade.styles.declare import GROUPS, Opt

#: the attribute of a parsed namespace that holds the flag table
TABLE = "_option_flags"


@dataclass
class Flag:
    """One generated flag: its declaration, and the parts whose option ``dest`` it sets."""

    dest: str
    flag: str
    opt: Opt
    default: Any
    parts: dict[str, str] = field(default_factory=dict)   # part -> option name (``dest``)
    deprecated: bool = False


def _shown_default(opt: Opt, default: Any) -> str:
    if default is None or default == () or callable(default) or opt.form == "append":
        return ""
    if opt.form == "switch":
        return " (default: on)" if default is True else ""
    if isinstance(default, tuple):
        return " (default: " + "x".join(str(v) for v in default) + ")" if opt.metavar == \
            "WxH" else ""
    return f" (default: {default})"


def _same_shape(a: Opt, b: Opt) -> bool:
    return (a.form, a.nargs, a.type, a.const) == (b.form, b.nargs, b.type, b.const)


def flag_table(classes: dict[str, type], skip=(), only=None) -> dict[str, Flag]:
    """option name -> :class:`Flag` of every option of ``classes`` (``{part: options
    class}``) that has a flag, deprecated names and presets (``preset_<name>``) included;
    ``TypeError`` where two parts declare one option in two shapes or one flag for two options
    (a bug: one flag must mean one thing)."""
    out: dict[str, Flag] = {}
    for part, cls in classes.items():
        for name, (opt, default) in cls.declarations().items():
            flag = opt.cli_flag(name)
            if flag is None or name in skip or (only is not None and name not in only):
                continue
            dest = name
            clash = [f.dest for f in out.values() if f.flag == flag and f.dest != name]
            if clash:
                raise TypeError(f"{flag}: the flag of two options, {clash[0]} and {name}")
            have = out.get(dest)
            if have is None:
                out[dest] = Flag(dest, flag, opt, default, {part: name})
            elif not _same_shape(have.opt, opt):
                raise TypeError(f"{flag}: declared in two shapes ({', '.join(have.parts)} and "
                                f"{part}); one flag must take one form")
            else:
                have.parts[part] = name
        for old, (new, _) in cls.DEPRECATED.items():
            dest = old
            if only is not None and new not in only:
                continue
            if dest in out and not out[dest].deprecated:
                continue
            out.setdefault(dest, Flag(dest, "--" + old.replace("_", "-"), Opt(group="picture"),
                                      None, {}, deprecated=True)).parts[part] = old
        for preset, (helptext, _) in (cls.PRESETS.items() if only is None else ()):
            dest = "preset_" + preset
            out.setdefault(dest, Flag(dest, "--" + preset, Opt(help=helptext, group="method"),
                                      None, {})).parts[part] = preset
    return out


def add_option_args(p: argparse.ArgumentParser, classes: dict[str, type], skip=(),
                    defaults: dict | None = None, only=None) -> None:
    """Add the flags of every option of ``classes`` (``{part: options class}``) to ``p``,
    grouped as the declarations group them; ``skip``: option names left out (a command's own
    flag stands for them), ``defaults``: flag dest -> the default shown in the help where the
    command differs (the picture size of a window), ``only``: just these options (a command
    that is no View, such as ``core porosity``, taking some of a part's options)."""
    table = flag_table(classes, skip, only)
    several = len(classes) > 1
    groups = {g: p.add_argument_group(title) for g, title in GROUPS.items()
              if any(f.opt.group == g for f in table.values())}
    for dest, f in table.items():
        g = groups[f.opt.group]
        if f.deprecated:   # the old names, hidden: one or more words, as they were typed
            g.add_argument(f.flag, dest=dest, nargs="+", default=argparse.SUPPRESS,
                           help=argparse.SUPPRESS)
            continue
        if dest.startswith("preset_"):
            g.add_argument(f.flag, dest=dest, action="store_true", default=argparse.SUPPRESS,
                           help=f.opt.help + (f" [{', '.join(f.parts)}]" if several else ""))
            continue
        shown = (defaults or {}).get(dest)
        helptext = f.opt.help + (f" (default: {shown})" if shown is not None
                                 else _shown_default(f.opt, f.default))
        if several and len(f.parts) < len(classes):
            helptext += f" [{', '.join(f.parts)}]"
        helptext = helptext.replace("%", "%%")
        kw: dict[str, Any] = {"dest": dest, "default": argparse.SUPPRESS, "help": helptext}
        if f.opt.form == "switch" and f.opt.off_flag is None:   # --flag, --no-flag
            g.add_argument(f.flag, action=argparse.BooleanOptionalAction, **kw)
        elif f.opt.form == "switch":
            g.add_argument(f.flag, action="store_const", const=True, **kw)
            kw["help"] = f"the opposite of {f.flag}"
            g.add_argument(f.opt.cli_off(dest), action="store_const", const=False, **kw)
        else:
            if f.opt.form == "append":
                kw["action"] = "append"
            elif f.opt.form == "optional":
                kw.update(nargs="?", const=f.opt.const)
            elif f.opt.nargs is not None:
                kw["nargs"] = f.opt.nargs
            if f.opt.type is not None:   # a float on a command line is a finite one
                kw["type"] = finite_float if f.opt.type is float else f.opt.type
            if f.opt.choices:
                kw["metavar"] = "{" + ",".join(str(c) for c in f.opt.choices) + "}"
            elif f.opt.metavar is not None:
                kw["metavar"] = f.opt.metavar
            g.add_argument(f.flag, **kw)
        for alias, value in f.opt.aliases:
            g.add_argument(alias, dest=dest, action="store_const", const=value,
                           default=argparse.SUPPRESS, help=f"the same as {f.flag} {value}"
                           if not isinstance(value, bool) else f"the same as "
                           f"{f.flag if value else f.opt.cli_off(dest)}")
    others = {a.dest for a in p._actions if a.dest not in table and a.dest != "help"}
    clash = sorted(others & set(table))
    if clash:
        raise TypeError(f"{', '.join(clash)}: a flag of this command already sets the "
                        "option of that name; give it another dest")
    tables = {**getattr(p, TABLE, {}), **table}
    setattr(p, TABLE, tables)
    p.set_defaults(**{TABLE: tables, TABLE + "_classes": dict(classes)})


def given_options(args, cls, part: str | None = None) -> dict:
    """The options typed on the command line for a View of options class ``cls`` (by name,
    only those given; a preset first, the flags given over it); one line for a flag the part
    does not take.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed by a parser :func:`add_option_args` filled.
    cls : type
        The part's options class.
    part : str, optional
        The part's name (default ``cls.PART``).
    """
    part = part or cls.PART
    table: dict[str, Flag] = getattr(args, TABLE, {})
    given = {d: getattr(args, d) for d in table if hasattr(args, d)}
    out: dict = {}
    for dest in given:
        f = table[dest]
        if dest.startswith("preset_"):
            if part not in f.parts:
                raise InputError(f"{f.flag}: not an option of the {part} view")
            out.update(cls.PRESETS[f.parts[part]][1])
    for dest, value in given.items():
        f = table[dest]
        if dest.startswith("preset_"):
            continue
        if part not in f.parts:
            raise InputError(f"{f.flag}: not an option of the {part} view (it applies to "
                             f"{', '.join(f.parts) or 'no part'})")
        if f.deprecated and isinstance(value, list) and len(value) == 1:
            value = value[0]
        out[f.parts[part]] = value
    return out


def flag_error(err: InputError, args) -> InputError:
    """``err`` with the option it names written as the flag the user typed (``exaggeration:
    ...`` -> ``--exaggeration: ...``), for the command line's one line.

    >>> import argparse
    >>> from geoshade.grid.options import GridOptions
    >>> p = argparse.ArgumentParser(); add_option_args(p, {"grid": GridOptions})
    >>> str(flag_error(InputError("gpu_memory: expected a size"), p.parse_args([])))
    '--gpu-memory: expected a size'
    """
    text = str(err)
    head, sep, rest = text.partition(":")
    name = head.split(" (")[0].strip()
    f = getattr(args, TABLE, {}).get(name)
    if not sep or f is None or " " in name:
        return err
    return InputError(f"{f.flag}{head[len(name):]}:{rest}")


def typed_options(args) -> dict:
    """Every option typed on the command line by name, for whichever part opens later
    (``view``, ``serve``): presets spelled out, deprecated names as their options take them;
    an option the opened part does not take is refused when it opens (one line).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed by a parser :func:`add_option_args` filled with several parts.
    """
    table: dict[str, Flag] = getattr(args, TABLE, {})
    out: dict = {}
    for dest, f in table.items():
        if dest.startswith("preset_") and hasattr(args, dest):
            from_part = next(iter(f.parts))
            out.update(classes_of(args)[from_part].PRESETS[f.parts[from_part]][1])
    for dest, f in table.items():
        if dest.startswith("preset_") or not hasattr(args, dest):
            continue
        value = getattr(args, dest)
        if f.deprecated and isinstance(value, list) and len(value) == 1:
            value = value[0]
        out[dest] = value
    return out


def classes_of(args) -> dict[str, type]:
    """The options classes a parser's flags were made from (``{part: class}``)."""
    return getattr(args, TABLE + "_classes", {})


__all__ = ["Flag", "add_option_args", "classes_of", "flag_error", "flag_table",
           "given_options", "typed_options"]
