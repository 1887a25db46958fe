"""Options own their vocabulary: every render subcommand's (and the viewer's) choices and
defaults are those of the options classes, and every field of every options class has a check
bound to it explicitly."""

from __future__ import annotations

import argparse
import dataclasses

import pytest

from geoshade.cli.main import build_parser
from geoshade.core.options import CoreOptions
from geoshade.grid.options import GridOptions
from geoshade.iso.options import IsoOptions
from geoshade.stacks.options import StacksOptions
from geoshade.styles.options import ViewOptions, checks

PARTS = {"core": CoreOptions, "grid": GridOptions, "iso": IsoOptions, "stacks": StacksOptions}
#: flag destinations named otherwise than the option they set
RENAMED = {"top_mode": "top"}
#: destinations that are no option of the part (inputs, outputs, hints, the run itself)
NOT_OPTIONS = {"help", "output", "stats", "frames", "pick", "camera_file", "save_camera",
               "shape", "dtype", "endian", "header", "spacing", "origin", "kind", "demo",
               "screenshot", "path", "keyword"}


def _subclasses(cls) -> list[type]:
    out = []
    for c in cls.__subclasses__():
        if c.__module__.startswith("geoshade."):
            out += [c, *_subclasses(c)]
    return out


#: every options class of the package (the parts' and any they extend)
ALL_OPTIONS = _subclasses(ViewOptions)


def _subparser(*names):
    p = build_parser()
    for name in names:
        sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
        p = sub.choices[name]
    return p


def _actions(*names):
    return [a for a in _subparser(*names)._actions if a.option_strings or a.choices]


def _field(cls, dest: str) -> str | None:
    name = RENAMED.get(dest, dest)
    fields = {f.name for f in dataclasses.fields(cls)}
    if name in fields or name in cls.CHOICES:
        return name
    return None


def _checked(cls, field: str, value):
    """What the options make of ``value`` for ``field`` (camera and colour shorthands too)."""
    opts = cls.parse(None, **{field: value})
    if field in ("view", "zoom"):
        return getattr(opts.camera, field)
    return getattr(opts, field)


@pytest.mark.parametrize("part", list(PARTS))
def test_render_choices_and_defaults_are_the_options(part):
    cls = PARTS[part]
    compared = 0
    for a in _actions(part, "render"):
        name = _field(cls, a.dest)
        if name is None or a.dest in NOT_OPTIONS:
            continue
        if a.choices is not None:
            assert tuple(a.choices) == tuple(cls.choices(name)), (
                f"{part} render {a.option_strings}: choices {a.choices} are not "
                f"{cls.__name__}.CHOICES[{name!r}] {cls.choices(name)}")
            compared += 1
        if a.default not in (None, False, [], argparse.SUPPRESS) and \
                not isinstance(a, argparse._StoreConstAction | argparse._StoreTrueAction):
            want = cls.default(name) if name not in ("view", "zoom") else \
                getattr(cls.default("camera"), name)
            assert _checked(cls, name, a.default) == want, (
                f"{part} render {a.option_strings}: default {a.default!r} is not "
                f"{cls.__name__}'s {want!r}")
            compared += 1
    assert compared >= 2, f"{part} render: nothing compared"


def test_render_size_default_is_the_options():
    for part, cls in PARTS.items():
        a = next(a for a in _actions(part, "render") if a.dest == "size")
        assert _checked(cls, "size", a.default) == cls.default("size"), part


def test_view_choices_are_the_options():
    """``geoshade view``'s choices are the parts' (a flag applies to the part that has it)."""
    compared = 0
    for a in _actions("view"):
        if a.choices is None or a.dest in NOT_OPTIONS:
            continue
        owners = [cls for cls in PARTS.values() if _field(cls, a.dest)]
        assert owners, f"view {a.option_strings}: no part has {a.dest}"
        for cls in owners:
            assert tuple(a.choices) == tuple(cls.choices(_field(cls, a.dest))), (
                f"view {a.option_strings}: {a.choices} vs {cls.__name__}")
        compared += 1
    assert compared >= 4


@pytest.mark.parametrize("cls", ALL_OPTIONS, ids=lambda c: c.__name__)
def test_every_field_has_a_check(cls):
    fields = [f.name for f in dataclasses.fields(cls)]
    missing = [f for f in fields if f not in cls._CHECKS]
    assert not missing, f"{cls.__name__}: no check for {missing}"
    for name, words in cls.CHOICES.items():  # every word of the vocabulary passes its check
        if name not in fields:
            continue
        for w in words:
            assert cls._CHECKS[name](w, None) == w, (cls.__name__, name, w)


def test_a_wrong_word_is_refused_in_one_line():
    from geoshade.errors import InputError

    with pytest.raises(InputError, match=r"^method: expected one of auto, raycast"):
        CoreOptions.parse(None, method="raytrace")
    with pytest.raises(InputError, match=r"^faults: expected one of show, highlight, hide"):
        GridOptions.parse(None, faults="blink")
    with pytest.raises(InputError, match=r"^cull: expected true or false"):
        GridOptions.parse(None, cull="maybe")


def test_misspelt_unbound_or_missing_checks_fail_when_the_class_is_made():
    with pytest.raises(TypeError, match="bound to levle, which is not one of its fields"):
        @dataclasses.dataclass(frozen=True)
        class A(ViewOptions):
            level: float = 0.0

            @staticmethod
            @checks("levle")
            def check_level(value, model=None):
                return value
    with pytest.raises(TypeError, match="check_level is bound to no field"):
        @dataclasses.dataclass(frozen=True)
        class B(ViewOptions):
            level: float = 0.0

            @staticmethod
            def check_level(value, model=None):
                return value
    with pytest.raises(TypeError, match="no check bound to level"):
        @dataclasses.dataclass(frozen=True)
        class C(ViewOptions):
            level: float = 0.0
    with pytest.raises(TypeError, match="in FLAGS/CHOICES is not one of its fields"):
        @dataclasses.dataclass(frozen=True)
        class D(ViewOptions):
            FLAGS = ("trasparent",)


def test_parse_is_pure_resolve_does_the_data_work():
    """``parse`` reads no voxel (``select='auto'`` stays a word); ``resolve`` finds Otsu's
    threshold once, and resolving again does nothing."""
    from geoshade import core
    from geoshade.compute.synthetic import synthetic_core

    vol = synthetic_core(16, dtype="uint8")
    opts = CoreOptions.parse(vol, select="auto")
    assert opts.select == "auto" and opts.select_auto is None
    res = opts.resolve(vol)
    sel, how = core.auto_select(vol)
    assert res.select == sel and res.select_auto["threshold"] == how["threshold"]
    assert res.resolve(vol) is res
