"""The stack ray caster (Graciano et al., Section 4): five GPU layouts behind one ray caster.

See :class:`geoshade.render.visuals.stacks.visual.StacksVisual` and
:mod:`geoshade.render.visuals.stacks.layouts`.
"""
