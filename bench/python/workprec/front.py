"""Work-precision analysis: the Pareto front of (error, cost) of an implementation, its cost at a
given error by log-log interpolation, and the cost ratio of two fronts at equal error."""
from __future__ import annotations

import math

SIGNIFICANT = 0.8   # a costlier setting joins the front only if it cuts the error by >= 20 %


def front(points):
    """Pareto front of (err, cost): errors ascending, costs descending. Walking from the
    cheapest point up, a costlier point is kept only if its error is below SIGNIFICANT times
    the best error so far: settings that sit on an error floor and differ there by rounding
    noise do not count as "more accurate at a higher cost"."""
    pts = sorted((c, e) for e, c in points if e is not None and c is not None
                 and math.isfinite(e) and math.isfinite(c))
    out, best = [], math.inf
    for c, e in pts:
        if e < SIGNIFICANT * best or not out:
            out.append((max(e, 1e-300), c))
            best = e
    return sorted(out)


def cost_at(fr, e):
    """Cost of front `fr` at error e by log-log interpolation. ('in', c) inside its range;
    ('below', c) when e is below its most accurate point (it would cost at least c, that
    point's cost); ('above', c) when e is above its least accurate point (it would cost at
    most c, the cost of its cheapest point, which is more accurate than e)."""
    if not fr:
        return "none", None
    e = max(e, 1e-300)
    if e < fr[0][0]:
        return "below", fr[0][1]
    if e > fr[-1][0]:
        return "above", fr[-1][1]
    for (e0, c0), (e1, c1) in zip(fr, fr[1:]):
        if e0 <= e <= e1:
            if e1 == e0:
                return "in", min(c0, c1)
            s = (math.log(e) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return "in", math.exp(math.log(c0) + s * (math.log(c1) - math.log(c0)))
    return "in", fr[0][1]


def compare(fmu_pts, base_pts, fmu_over_base: bool, need: float):
    """For each point of the FMU's front inside (or below) the baseline front's error range:
    the cost ratio at equal error, (err, fmu cost, base cost, ratio, where, conclusive).
    fmu_over_base: ratio = FMU/baseline and the target is ratio <= need; else baseline/FMU
    and ratio >= need. A ratio at an FMU point more accurate than the whole baseline front
    ('below') is one-sided (the baseline would cost more than its most accurate point): it is
    conclusive only if it meets the target anyway; one at an FMU point less accurate than the
    whole baseline front ('above': the baseline is cheaper than its cheapest point there) only
    if it misses the target anyway. Returns (rows, verdict, worst conclusive)."""
    ff, bf = front(fmu_pts), front(base_pts)
    res = []
    for e, c in ff:
        where, cb = cost_at(bf, e)
        if cb is None:
            continue
        ratio = c / cb if fmu_over_base else cb / c
        meets = ratio <= need if fmu_over_base else ratio >= need
        conclusive = where == "in" or (where == "below" and meets) or \
            (where == "above" and not meets)
        res.append((e, c, cb, ratio, where, conclusive))
    concl = [r for r in res if r[5]]
    if not concl:
        return res, "n/a", None
    worst = (max if fmu_over_base else min)(concl, key=lambda r: r[3])
    ok = all((r[3] <= need) if fmu_over_base else (r[3] >= need) for r in concl)
    return res, "PASS" if ok else "FAIL", worst
