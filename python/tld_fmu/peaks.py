"""Peaks of a response curve located to a stated tolerance, not read off the grid.

A sweep's grid only says where a peak is to within one grid spacing, and near a sharp
resonance the largest grid value can be far below the peak (a 0.05 grid misses a 1 % damped
peak by tens of per cent). Every peak the project reports is therefore refined: the grid's local
maximum at x_i brackets a maximum between its neighbours x_{i-1} and x_{i+1}, and a golden-section
search (the bracketing kept at every step, as in Brent's method without the parabolic steps,
which noisy co-simulation peaks do not reward) shrinks that bracket until it is no wider than
2 xtol. The reported peak is the best point evaluated, within xtol of the maximum of the
bracketed hump; the error in its height is second order in xtol.

The searches are generators that ask for one x at a time, so that many of them (several peaks,
several curves, several cases of a study) advance in lockstep and each round's evaluations run in
parallel: `refine_curves(curves, evaluate, xtol)` with `evaluate` a batch (parallel) map.
`refine_peak(f, xs)` is the one-curve, one-peak, serial form.

A grid maximum at either end of the grid cannot be bracketed: it is reported as found, with
`bounded = False` (the true peak may lie outside the sweep; widen it)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Hashable, Iterable, Sequence

# the golden section's smaller fraction, (3 - sqrt 5) / 2
R = (3.0 - math.sqrt(5.0)) / 2.0


@dataclass
class Peak:
    x: float                       # where the maximum is (within xtol if bounded)
    y: float                       # the response there (the largest value evaluated)
    grid_x: float                  # the grid's own local maximum, for comparison
    grid_y: float
    xtol: float                    # the stated tolerance on x
    bounded: bool = True           # False: the grid maximum is at an end of the grid
    points: list[tuple[float, float]] = field(default_factory=list)   # the refinement's evaluations

    @property
    def gain(self) -> float:
        """How much the refinement raised the peak over the grid's (y / grid_y)."""
        return self.y / self.grid_y if self.grid_y else math.inf


def local_maxima(ys: Sequence[float], rel: float = 0.0) -> list[int]:
    """Indices of the grid's local maxima (y_i >= both neighbours, > at least one; the ends
    count when they exceed their one neighbour). rel > 0 drops maxima lower than rel times the
    curve's largest value (ripples)."""
    n = len(ys)
    top = max(ys)
    out = []
    for i in range(n):
        left = ys[i - 1] if i > 0 else -math.inf
        right = ys[i + 1] if i < n - 1 else -math.inf
        if ys[i] >= left and ys[i] >= right and (ys[i] > left or ys[i] > right) and ys[i] >= rel * top:
            out.append(i)
    return out


def golden_search(a, b, c, fa, fb, fc, xtol):
    """Generator: maximise within the bracket a < b < c, f(b) >= f(a), f(c). Yields the next x
    to evaluate and receives f(x); returns (x, f(x)) of the best point once c - a <= 2 xtol."""
    if not (a < b < c):
        raise ValueError(f"not a bracket: {a}, {b}, {c}")
    while c - a > 2.0 * xtol:
        # the new point in the larger of the two intervals, at the golden fraction from b
        x = b + R * (c - b) if c - b > b - a else b - R * (b - a)
        fx = yield x
        if fx > fb:
            if x > b:
                a, fa = b, fb
            else:
                c, fc = b, fb
            b, fb = x, fx
        elif x > b:
            c, fc = x, fx
        else:
            a, fa = x, fx
    return b, fb


def refine_curves(curves: dict[Hashable, tuple[Sequence[float], Sequence[float]]],
                  evaluate: Callable[[list[tuple[Hashable, float]]], Iterable[float]],
                  xtol: float, every: bool = True, rel: float = 0.1) -> dict[Hashable, list[Peak]]:
    """Refine the peaks of several sampled curves together.

    curves: {key: (xs, ys)}, xs ascending. evaluate([(key, x), ...]) -> the curves' values there
    (in order; run them in parallel if you can). every=True refines each local maximum of a
    curve at least rel times its largest grid value (a tuned damper's two peaks), every=False only
    the largest. Returns {key: [Peak, ...]} in ascending x; the searches of all curves advance
    in lockstep, one evaluation each per call of `evaluate`."""
    peaks: dict[Hashable, list[Peak]] = {k: [] for k in curves}
    active = []   # (key, Peak, generator, pending x)
    for key, (xs, ys) in curves.items():
        xs, ys = [float(x) for x in xs], [float(y) for y in ys]
        if len(xs) != len(ys) or len(xs) < 2:
            raise ValueError(f"curve {key!r}: need as many values as grid points, at least 2")
        idx = local_maxima(ys, rel) if every else [max(range(len(ys)), key=ys.__getitem__)]
        for i in idx:
            p = Peak(xs[i], ys[i], xs[i], ys[i], xtol, bounded=0 < i < len(xs) - 1)
            peaks[key].append(p)
            if p.bounded:
                g = golden_search(xs[i - 1], xs[i], xs[i + 1], ys[i - 1], ys[i], ys[i + 1], xtol)
                try:
                    active.append([key, p, g, next(g)])
                except StopIteration as stop:      # the grid is already fine enough
                    p.x, p.y = stop.value
    while active:
        values = list(evaluate([(key, x) for key, _, _, x in active]))
        still = []
        for item, y in zip(active, values):
            key, p, g, x = item
            y = float(y)
            p.points.append((x, y))
            try:
                item[3] = g.send(y)
                still.append(item)
            except StopIteration as stop:
                p.x, p.y = stop.value
        active = still
    return peaks


def refine_peak(f: Callable[[float], float], xs: Sequence[float], ys: Sequence[float] | None = None,
                xtol: float = 1e-3) -> Peak:
    """The largest peak of f sampled on the grid xs (values ys, computed if not given), refined
    to xtol by golden-section search, serially."""
    if ys is None:
        ys = [f(x) for x in xs]
    return refine_curves({0: (xs, ys)}, lambda batch: [f(x) for _, x in batch], xtol, every=False)[0][0]


def highest(peaks: Iterable[Peak]) -> Peak:
    """The highest of some peaks."""
    return max(peaks, key=lambda p: p.y)


def describe(p: Peak, unit: str = "", scale: float = 1.0, xname: str = "x") -> str:
    """One line: the refined peak, the grid's, and the tolerance."""
    s = (f"{scale * p.y:.4g}{unit} at {xname} = {p.x:.4f} +- {p.xtol:g} "
         f"(grid: {scale * p.grid_y:.4g}{unit} at {p.grid_x:.4f}, {len(p.points)} refinement runs)")
    return s if p.bounded else s + " AT THE EDGE OF THE GRID: the peak may lie outside it"
