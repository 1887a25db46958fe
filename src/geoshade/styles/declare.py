"""Options declared once: what every front end reads about an option field.

A field of an options class (:class:`geoshade.styles.options.ViewOptions` and the parts') is
declared with :func:`option`, which puts one :class:`Opt` into the field's metadata: its help
text, group, whether it can change on an open View (``live``), its words (``choices``), its
command-line flag and form, its panel control and an example value. From that one declaration
come

- the checks of the words and the true/false fields (:func:`geoshade.styles.checks.bind_checks`),
- the flags of ``<part> render``, ``view`` and ``serve`` (:mod:`geoshade.cli.options`),
- the controls of the viewers' panels (:func:`controls`),
- the names :meth:`View.update <geoshade.render.view.View.update>` folds into the camera and
  colour value objects (:data:`geoshade.styles.options.SHORTHANDS`),
- the live-change parity test (``update(x)`` draws what a View opened with ``x`` draws).

>>> from dataclasses import dataclass, fields
>>> @dataclass(frozen=True)
... class Demo:
...     faults: str = option("show", choices=("show", "hide"), help="fault faces")
>>> opt_of(fields(Demo)[0]).choices, opt_of(fields(Demo)[0]).cli_flag("faults")
(('show', 'hide'), '--faults')
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from geoshade.styles.checks import _option_fields

#: the groups options are shown in (CLI help sections and panel groups), in this order
GROUPS = {
    "shown": "what is shown",
    "cut": "cutting and filtering",
    "colour": "colours",
    "wells": "wells",
    "camera": "camera",
    "picture": "picture",
    "method": "drawing method",
    "cluster": "memory, clusters and previews",
}

#: the forms of a command-line flag
FORMS = ("value", "switch", "optional", "append")

_AUTO = object()


@dataclass(frozen=True)
class Opt:
    """One option's declaration (see the module's description).

    help:     one line for ``--help``, tooltips and docs
    group:    one of :data:`GROUPS`
    live:     an open View changes it with ``update()``/a control; False: fixed when it opens
              (``update`` refuses it in one line)
    choices:  the words it takes (checked case-insensitively; the panels' select)
    flag:     its command-line flag (default ``--name-with-dashes``); None: none (Python only)
    form:     ``value`` (``--flag VALUE``), ``switch`` (``--flag``/``--no-flag``; ``off_flag``
              names the second where it is not ``--no-flag``), ``optional`` (``--flag`` alone
              means ``const``) or ``append`` (repeated: ``--flag A --flag B``)
    nargs, metavar, type: as argparse takes them (``type`` turns the text into the value the
              check takes; without it the check gets the text)
    const:    the value of a bare ``optional`` flag
    aliases:  ``(flag, value)`` pairs: more bare flags that set a value (``--paper-trefoil``)
    off_flag: a ``switch``'s flag for False (default ``--no-<flag>``)
    control:  the panel control type (:data:`CONTROLS`), None: from the declaration, ``""``:
              no control (the command line and Python only)
    example:  a value other than the default (or ``f(model)`` giving one) for docs and tests
    limits:   ``(lo, hi)`` of a number's control (the check says what is allowed)
    """

    help: str = ""
    group: str = "picture"
    live: bool = True
    choices: tuple | None = None
    flag: Any = _AUTO
    form: str = "value"
    nargs: int | str | None = None
    metavar: Any = None
    type: Callable | None = None
    const: Any = None
    aliases: tuple = ()
    off_flag: str | None = None
    control: str | None = None
    example: Any = None
    limits: tuple | None = None

    def __post_init__(self) -> None:
        if self.group not in GROUPS:
            raise TypeError(f"option group {self.group!r}: expected one of {', '.join(GROUPS)}")
        if self.form not in FORMS:
            raise TypeError(f"option form {self.form!r}: expected one of {', '.join(FORMS)}")

    def cli_flag(self, name: str) -> str | None:
        """The flag of option ``name`` (None: it has none)."""
        if self.flag is _AUTO:
            return "--" + name.replace("_", "-")
        return self.flag

    def cli_off(self, name: str) -> str | None:
        """A switch's flag for False."""
        flag = self.cli_flag(name)
        if self.form != "switch" or flag is None:
            return None
        return self.off_flag or "--no-" + flag[2:]

    def flags(self, name: str) -> list[str]:
        """Every flag that sets option ``name`` (the flag, a switch's off flag, the aliases)."""
        out = [f for f in (self.cli_flag(name), self.cli_off(name)) if f]
        return out + [a for a, _ in self.aliases]


#: panel control types a declaration names: the plain ones (made from the declaration alone)
#: and those whose choices come from the data (:mod:`geoshade.viewer.controls`)
CONTROLS = ("select", "check", "tristate", "number", "pair", "ints", "text", "colormap",
            "property", "step", "steps", "color_by", "keyword", "wells", "selection", "materials",
            "section", "drape", "ijk", "ranges", "vectors")


def option(default: Any = None, *, factory: Callable | None = None, **declaration) -> Any:
    """A dataclass field with its :class:`Opt` (``declaration``) and its default (``factory``
    for a mutable or computed default)."""
    meta = {"opt": Opt(**declaration)}
    if factory is not None:
        return dataclasses.field(default_factory=factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def opt_of(field: dataclasses.Field) -> Opt | None:
    """The declaration of a dataclass field (None: the field was not declared)."""
    return field.metadata.get("opt") if field.metadata else None


def control_type(opt: Opt, default: Any) -> str:
    """The panel control an option gets: ``select`` for words, ``check`` for true/false,
    ``tristate`` for auto/true/false, ``pair``/``ints`` for fixed-length numbers, ``number``
    for a number, else ``text``; ``""`` for none."""
    if opt.control is not None:
        if opt.control and opt.control not in CONTROLS:
            raise TypeError(f"control {opt.control!r}: expected one of {', '.join(CONTROLS)}")
        return opt.control
    if opt.choices:
        return "select"
    if opt.form == "switch":
        return "check" if isinstance(default, bool) else "tristate"
    if opt.nargs == 2:
        return "pair"
    if isinstance(opt.nargs, int):
        return "ints"
    if (isinstance(default, int | float) and not isinstance(default, bool)) or \
            opt.type in (int, float):
        return "number"
    return "text"


def _declared(cls) -> dict[str, Opt]:
    """field -> :class:`Opt` of an options class as it is made (its bases already dataclasses,
    its own fields still ``dataclasses.Field`` class attributes)."""
    out: dict[str, Opt] = {}
    for klass in reversed(cls.__mro__):
        own = vars(klass)
        if "__dataclass_fields__" in own:
            items = [(f.name, opt_of(f)) for f in own["__dataclass_fields__"].values()]
        else:
            items = [(n, opt_of(v)) for n, v in own.items() if isinstance(v, dataclasses.Field)]
        for name, opt in items:
            if opt is not None:
                out[name] = opt
    return out


def _field_default(cls, name: str):
    for klass in cls.__mro__:
        v = vars(klass).get(name, dataclasses.MISSING)
        made = vars(klass).get("__dataclass_fields__", {})
        if name in made:
            v = made[name]
        if isinstance(v, dataclasses.Field):
            if v.default is not dataclasses.MISSING:
                return v.default
            return v.default_factory() if v.default_factory is not dataclasses.MISSING else None
        if v is not dataclasses.MISSING:
            return v
    return None


def derive_tables(cls, base, views) -> None:
    """The class's declarations, and the words (``CHOICES``) and true/false fields (``FLAGS``)
    they give, which the checks and older readers use."""
    for table in ("FLAGS", "CHOICES"):
        if cls is not base and table in vars(cls):
            raise TypeError(f"{cls.__name__}: {table} is made from the declarations; declare "
                            "the field with option(choices=...) or option(form='switch')")
    cls._OPTS = _declared(cls)
    plain = [n for n in _option_fields(cls) if n not in cls._OPTS]
    if plain:
        raise TypeError(f"{cls.__name__}.{plain[0]}: not declared; declare every option field "
                        "with option(default, help=..., group=...) (styles/declare.py)")
    choices = {"view": tuple(views)}
    flags = []
    nullable = []
    for name, opt in cls._OPTS.items():
        if opt.choices:
            choices[name] = tuple(opt.choices)
            if _field_default(cls, name) is None:
                nullable.append(name)
        if opt.form == "switch" and isinstance(_field_default(cls, name), bool):
            flags.append(name)
    cls.CHOICES = choices
    cls.FLAGS = tuple(flags)
    cls._NULLABLE = tuple(nullable)


__all__ = ["CONTROLS", "GROUPS", "Opt", "control_type", "derive_tables", "opt_of", "option"]
