"""Number and label formats shared by the report, its findings and the plots."""
from __future__ import annotations


def fmt_e(v, d=2):
    if v is None:
        return "—"
    if v == 0:
        return "0"
    return f"{v:.{d}e}"


def fmt_ns(v):
    if v is None:
        return "—"
    if v >= 1e6:
        return f"{v:.3g}".replace("e+0", "e").replace("e+", "e")
    return f"{v:,.0f}" if v >= 100 else f"{v:.1f}"


def dt_label(dt):
    return f"{dt * 1e3:g} ms"
