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
from geoshade.styles.declare import GROUPS, opt_of, option
from geoshade.styles.options import ViewOptions, checks

PARTS = {"core": CoreOptions, "grid": GridOptions, "iso": IsoOptions, "stacks": StacksOptions}


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


def _flags(parser) -> set[str]:
    return {s for a in parser._actions for s in a.option_strings}


def _declared_flags(cls) -> dict[str, list[str]]:
    return {name: opt.flags(name) for name, (opt, _) in cls.declarations().items()
            if opt.cli_flag(name)}


@pytest.mark.parametrize("cls", ALL_OPTIONS, ids=lambda c: c.__name__)
def test_every_field_is_declared_with_help_and_a_group(cls):
    for f in dataclasses.fields(cls):
        opt = opt_of(f)
        assert opt is not None, f"{cls.__name__}.{f.name}: not declared with option()"
        assert opt.help.strip(), f"{cls.__name__}.{f.name}: no help"
        assert opt.group in GROUPS


@pytest.mark.parametrize("part", list(PARTS))
def test_render_view_and_serve_take_every_drawing_option_of_the_part(part):
    """Issue 30: the flags come from the declarations, so ``view`` and ``serve`` take every
    flag ``<part> render`` takes (and the same words)."""
    declared = _declared_flags(PARTS[part])
    assert len(declared) >= 20
    for cmd in ((part, "render"), ("view",), ("serve",)):
        have = _flags(_subparser(*cmd))
        missing = sorted(f for fl in declared.values() for f in fl if f not in have)
        assert not missing, f"{' '.join(cmd)} lacks {missing}"
    render = {a.dest: a for a in _subparser(part, "render")._actions}
    view = {a.dest: a for a in _subparser("view")._actions}
    for name in declared:
        assert render[name].option_strings == view[name].option_strings, name


def test_a_flag_the_opened_part_does_not_take_is_one_line():
    from geoshade.cli.options import given_options
    from geoshade.errors import InputError

    args = _subparser("view").parse_args(["x", "--edges", "quad"])
    assert given_options(args, GridOptions) == {"edges": "quad"}
    with pytest.raises(InputError, match=r"^--edges: not an option of the core view \(it "
                                         r"applies to grid\)"):
        given_options(args, CoreOptions)


def test_generated_flags_give_the_options_the_python_api_takes():
    from geoshade.cli.options import given_options

    args = _subparser("grid", "render").parse_args(
        ["c", "-o", "o.png", "--no-cull", "--edges", "--color-range", "0", "1", "--linear",
         "--continuous", "--view", "top", "--ortho", "--gpu-memory", "8G", "--no-sim-wells"])
    got = given_options(args, GridOptions)
    assert got == {"cull": False, "edges": "quad", "color_range": [0.0, 1.0], "log": False,
                   "categorical": False, "view": "top", "ortho": True, "gpu_memory": "8G",
                   "sim_wells": False}
    opts = GridOptions.parse(None, **got)
    assert (opts.cull, opts.edges, opts.color.range, opts.color.log, opts.camera.view,
            opts.gpu_memory) == (False, "quad", (0.0, 1.0), False, "top", 8 << 30)
    core = given_options(_subparser("core", "render").parse_args(
        ["v", "-o", "o.png", "--paper-trefoil", "--select", "auto", "--bricks", "0"]),
        CoreOptions)
    assert CoreOptions.parse(None, **core).trefoil_mode == "paper"
    assert CoreOptions.parse(None, **core).bricks is False
    iso = given_options(_subparser("iso", "render").parse_args(
        ["f", "-o", "o.png", "--paper", "--patch-level", "16"]), IsoOptions)
    assert iso == {"patch_level": 16, "skip_patches": False, "slice_axis": "z",
                   "mesh_cache": False}


def test_one_flag_in_two_shapes_or_for_two_options_is_refused():
    from geoshade.cli.options import flag_table
    from geoshade.styles.declare import option

    @dataclasses.dataclass(frozen=True)
    class Odd(ViewOptions):
        faults: str = option("x", help="h", type=int)

        @staticmethod
        @checks("faults")
        def check_faults(value, model=None):
            return value

    with pytest.raises(TypeError, match="declared in two shapes"):
        flag_table({"grid": GridOptions, "odd": Odd})


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
            level: float = option(0.0, help="the level")

            @staticmethod
            @checks("levle")
            def check_level(value, model=None):
                return value
    with pytest.raises(TypeError, match="check_level is bound to no field"):
        @dataclasses.dataclass(frozen=True)
        class B(ViewOptions):
            level: float = option(0.0, help="the level")

            @staticmethod
            def check_level(value, model=None):
                return value
    with pytest.raises(TypeError, match="no check bound to level"):
        @dataclasses.dataclass(frozen=True)
        class C(ViewOptions):
            level: float = option(0.0, help="the level")
    with pytest.raises(TypeError, match="FLAGS is made from the declarations"):
        @dataclasses.dataclass(frozen=True)
        class D(ViewOptions):
            FLAGS = ("trasparent",)
    with pytest.raises(TypeError, match=r"E\.level: not declared"):
        @dataclasses.dataclass(frozen=True)
        class E(ViewOptions):
            level: float = 0.0


def test_parse_is_pure_resolve_does_the_data_work():
    """``parse`` reads no voxel (``select='auto'`` stays a word); ``resolve`` finds Otsu's
    threshold once, and resolving again does nothing."""
    from geoshade import core
    from geoshade.compute.voxels.synthetic import synthetic_core

    vol = synthetic_core(16, dtype="uint8")
    opts = CoreOptions.parse(vol, select="auto")
    assert opts.select == "auto" and opts.select_auto is None
    res = opts.resolve(vol)
    sel, how = core.auto_select(vol)
    assert res.select == sel and res.select_auto["threshold"] == how["threshold"]
    assert res.resolve(vol) is res
