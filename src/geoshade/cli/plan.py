"""The memory plan in the commands: made before anything is loaded (:func:`geoshade.api.plan`),
said on stderr in one line, applied to the reading (the route's reader, a mapped file read by
blocks) and the options (a bricks route's GPU budget), and kept in the stats JSON; or, when no
route fits, the one-line refusal with the figures and the route to take (exit 6) before any
work.

The line is said (``geoshade: plan: ...``) when the plan changes something or is close to the
limits: a route other than the plain one (not the one the user asked for by name, as
``--distributed`` asks for the cluster), a ``--memory`` budget, an address-space limit
(``ulimit -v``), or a first route needing more than :data:`SAY_SHARE` of the memory available.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from geoshade.api import plan as make_plan
from geoshade.cli.main import volume_hints
from geoshade.io.paths import NotEnoughMemoryError
from geoshade.io.plan import Plan

#: the plan is said when its first route needs more than this share of the memory available
SAY_SHARE = 0.25


@dataclass
class Planned:
    """What :func:`before_loading` decided: the plan (None: there is none) and how to read."""

    plan: Plan | None = None
    options: dict = field(default_factory=dict)

    def read(self, load):
        """The model, read by the chosen route's reader (else ``load()``) and adapted."""
        route = None if self.plan is None else self.plan.chosen
        model = route.load() if route is not None and route.load is not None else load()
        if route is not None and route.adapt is not None:
            if isinstance(model, tuple):
                return (route.adapt(model[0]), *model[1:])
            return route.adapt(model)
        return model

    def stats(self) -> dict:
        """``{"plan": ...}`` for the stats JSON ({} without a plan)."""
        return {} if self.plan is None else {"plan": self.plan.stats()}


def _hints(args) -> dict:
    hints = volume_hints(args)
    for name in ("dataset", "offset"):
        if getattr(args, name, None) is not None:
            hints[name] = getattr(args, name)
    return hints


def said(p: Plan) -> bool:
    """Whether the plan is worth a line on stderr (see the module)."""
    m = p.machine
    changed = p.chosen is not p.first and (p.chosen is None or p.chosen.name != p.forced)
    return (changed or m.ram_source == "--memory" or m.address_space is not None
            or (m.ram is not None and p.first.ram > SAY_SHARE * m.ram))


def before_loading(kind: str, args, options, inputs=()) -> Planned:
    """The plan of drawing ``inputs[0]`` with the parsed ``options`` of part ``kind``: said on
    stderr (see :func:`said`), or refused in one line (:class:`NotEnoughMemoryError`)."""
    path = next((str(p) for p in inputs if p is not None), None)
    if path is None or kind not in ("core", "grid", "stacks") or getattr(args, "level", None) \
            is not None or not Path(path).exists():
        return Planned()
    p = make_plan(path, as_=kind, options=options, memory=getattr(options, "memory", None),
                  gpu_memory=getattr(options, "gpu_memory", None), **_hints(args))
    if p is None:
        return Planned()
    if p.chosen is None:
        raise NotEnoughMemoryError(p.refusal())
    if said(p):
        print(f"geoshade: plan: {p.line()}", file=sys.stderr)
    opts: dict[str, Any] = dict(p.chosen.options)
    return Planned(p, opts)


__all__ = ["SAY_SHARE", "Planned", "before_loading", "said"]
