"""``geoshade bench PART``: run the benchmarks in the source tree's ``benchmarks/`` folder."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

from geoshade.errors import InputError

PARTS = ("core", "iso", "grid", "stacks", "scale", "distributed", "composite", "web")


def register(sub) -> None:
    p = sub.add_parser("bench", help="benchmarks against peers (writes benchmarks/RESULTS.md)")
    p.add_argument("part", choices=PARTS, help="which part to measure")
    p.add_argument("--full", action="store_true", help="include the largest sizes (slow)")
    p.add_argument("--quick", action="store_true", help="smallest sizes only (smoke run)")
    p.add_argument("--no-peers", action="store_true", help="skip PyVista/VTK")
    p.add_argument("--repeats", type=int, metavar="N",
                   help="runs of every config, each its own process (bench iso; default 3)")
    p.add_argument("--size", default="1024x768", metavar="WxH")
    p.add_argument("-o", "--output", metavar="DIR",
                   help="where to write RESULTS.md and JSON (default: benchmarks/)")
    p.set_defaults(func=run)


def benchmarks_dir() -> Path:
    here = Path(__file__).resolve()
    for parent in here.parents:
        cand = parent / "benchmarks"
        if (cand / f"bench_{PARTS[0]}.py").is_file():
            return cand
    raise InputError("bench: the benchmarks/ folder was not found; run geoshade bench from a "
                     "source checkout installed with pip install -e .")


def run(args) -> int:
    folder = benchmarks_dir()
    path = folder / f"bench_{args.part}.py"
    spec = importlib.util.spec_from_file_location(f"geoshade_bench_{args.part}", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod.main(args, folder)
