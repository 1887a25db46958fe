"""A deterministic synthetic unstable displacement: fingers of water growing into oil.

The displacing fluid enters through the ``x = 0`` face and moves towards ``+x``. Its front
``x_f(y, z, t)`` advances with the mean velocity and carries a perturbation made of Gaussian
"fingers" at random ``(y, z)`` positions plus a weak smooth noise; the perturbation's amplitude
grows faster than the mean front (viscous fingering is unstable), so fingers lengthen with time:

    x_f(y, z, t) = U t (1 + a (t / T)^1.5 P(y, z))

and the saturation is a smooth step across the front with a Buckley–Leverett-like decline
behind it:

    S = S_wi + (1 - S_or - S_wi) * σ((x_f - x) / w) * (0.8 + 0.2 (1 - x / x_f)^+)

Pressure (for colouring) falls linearly from the injector to the producer, less steeply behind
the front (water is less viscous). Steps are computed when read, so large sizes cost memory for
one step at a time.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from geoshade.errors import InputError
from geoshade.models.field import FieldSeries

#: connate water and residual oil saturation of the synthetic rock
S_WI, S_OR = 0.1, 0.15


class _LazySteps(Sequence):
    """(T, nz, ny, nx) float32 array-like whose steps are computed on access."""

    def __init__(self, fn, nsteps: int, shape_zyx: tuple[int, int, int]):
        self._fn, self._n = fn, int(nsteps)
        self.shape = (self._n, *shape_zyx)
        self.dtype = np.dtype(np.float32)

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self._fn(i) for i in range(*k.indices(self._n))]
        k = int(k)
        if not -self._n <= k < self._n:
            raise IndexError(k)
        return self._fn(k % self._n)


def _smooth_noise(rng, shape, passes: int) -> np.ndarray:
    """Zero-mean, unit-std noise smoothed by repeated [1, 2, 1] / 4 box passes (periodic)."""
    a = rng.standard_normal(shape)
    for _ in range(passes):
        for ax in range(a.ndim):
            a = 0.25 * (np.roll(a, 1, ax) + 2 * a + np.roll(a, -1, ax))
    a -= a.mean()
    return a / (a.std() or 1.0)


def displacement_field(shape=(64, 48, 48), steps: int = 8, fingers: int = 7, seed: int = 0,
                       spacing=(1.0, 1.0, 1.0), width: float = 1.5,
                       growth: float = 0.9) -> FieldSeries:
    """Water saturation of a synthetic unstable displacement over ``steps`` time steps.

    Parameters
    ----------
    shape : (nx, ny, nz)
        Nodes along x (the flow direction), y and z.
    steps : int
        Time steps; step ``k`` is time ``(k + 1) / steps``; at the last step the mean front has
        crossed ~45 % of the length and the longest fingers ~85 %.
    fingers : int
        Number of fingers.
    seed : int
        Random seed: the same arguments always give the same field.
    spacing : (3,) float
        Node spacing (x, y, z).
    width : float
        Thickness of the front (in nodes).
    growth : float
        Finger amplitude at the last step, relative to the mean front position.

    Returns
    -------
    FieldSeries
        ``name="SWAT"``, values in ``[S_WI, 1 - S_OR]`` (float32), one property ``"PRESSURE"``
        (bar); ``meta["levels"]`` suggests a level (0.5).

    Examples
    --------
    >>> f = displacement_field((24, 16, 12), steps=3, seed=1)
    >>> f.nsteps, f.shape, f.name
    (3, (12, 16, 24), 'SWAT')
    >>> s0, s2 = f.step(0), f.step(2)
    >>> bool((s2 >= 0.5).sum() > (s0 >= 0.5).sum())  # the water body grows
    True
    >>> bool(np.array_equal(s2, displacement_field((24, 16, 12), steps=3, seed=1).step(2)))
    True
    """
    try:
        nx, ny, nz = (int(v) for v in shape)
    except (TypeError, ValueError):
        raise InputError(f"shape: expected 3 integers (nx, ny, nz), got {shape!r}") from None
    if min(nx, ny, nz) < 2:
        raise InputError(f"shape: expected at least 2 nodes per axis, got {(nx, ny, nz)}")
    if int(steps) < 1 or int(fingers) < 0:
        raise InputError(f"steps must be >= 1 and fingers >= 0, got {steps}, {fingers}")
    steps = int(steps)
    rng = np.random.default_rng(seed)
    y = np.arange(ny, dtype=np.float64)[None, :]
    z = np.arange(nz, dtype=np.float64)[:, None]
    # fingers: Gaussian bumps in the (y, z) plane, of random strength and thickness
    pert = np.zeros((nz, ny))
    cy = rng.uniform(0.1, 0.9, fingers) * (ny - 1)
    cz = rng.uniform(0.1, 0.9, fingers) * (nz - 1)
    strength = rng.uniform(0.5, 1.0, fingers)
    radius = rng.uniform(0.06, 0.12, fingers) * min(ny, nz) + 1.0
    for f in range(fingers):  # a handful of fingers, each a whole-plane array expression
        pert += strength[f] * np.exp(-((y - cy[f]) ** 2 + (z - cz[f]) ** 2) / (2 * radius[f] ** 2))
    # a weak smooth noise (correlation length ~4 % of the section) roughens the front
    sigma = 0.04 * min(ny, nz)
    pert += 0.12 * _smooth_noise(rng, (nz, ny), passes=max(2, round(2 * sigma * sigma)))
    pert -= pert.mean()
    pert /= max(float(np.abs(pert).max()), 1e-9)
    x = np.arange(nx, dtype=np.float64)
    length = nx - 1
    dS = 1.0 - S_OR - S_WI

    def front(k: int) -> np.ndarray:
        t = (k + 1) / steps
        mean = 0.45 * length * t
        return mean * (1.0 + growth * t**1.5 * pert)  # (nz, ny)

    def saturation(k: int) -> np.ndarray:
        xf = np.maximum(front(k), 1e-6)[:, :, None]
        step = 0.5 * (1.0 + np.tanh((xf - x) / (2.0 * width)))
        behind = 0.8 + 0.2 * np.clip(1.0 - x / xf, 0.0, 1.0)
        return (S_WI + dS * step * behind).astype(np.float32)

    def pressure(k: int) -> np.ndarray:
        xf = np.maximum(front(k), 1e-6)[:, :, None]
        xi = np.broadcast_to(x, (nz, ny, nx))
        water = np.minimum(xi, xf) * 0.4 + np.maximum(xi - xf, 0.0)
        total = 0.4 * xf + (length - xf)
        return (300.0 - 100.0 * water / total).astype(np.float32)

    return FieldSeries(
        _LazySteps(saturation, steps, (nz, ny, nx)),
        spacing=spacing,
        name="SWAT",
        unit="fraction",
        times=[f"t = {(k + 1) / steps:.3f}" for k in range(steps)],
        properties={"PRESSURE": _LazySteps(pressure, steps, (nz, ny, nx))},
        source="synthetic displacement",
        meta={"format": "synthetic", "seed": seed, "levels": [0.5],
              "property_units": {"PRESSURE": "bar"}},
    )
