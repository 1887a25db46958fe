"""What the test suites of geoshade (and of code that extends it) share: the conformance checks
every part's View must pass, made from the options' declarations.

- :mod:`geoshade.testing.parity` -- live-change parity: for every option of every part,
  ``update(x)`` then ``draw()`` gives the picture a View opened with ``x`` gives, pixel for
  pixel; an option fixed at opening is refused by ``update`` in one line.
"""
