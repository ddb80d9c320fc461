"""Observed orders of convergence from asymptotic runs only.

A least-squares slope over every run of a method reports a number even where the coarsest run is not yet
in the asymptotic range: on B6, energy-collocation's errors 1.4e-3, 9.9e-6 at h = 8e-4, 4e-4 gave a "7.1"
and its multiplier errors a "15" (the coarse run's transient, not an order). The rule here:

1. a run enters only if its error is finite and above ``floor_factor`` times the reference's own error
   bound (below that the error is the reference's);
2. the local orders ``p_i = log(e_i / e_{i+1}) / log(h_i / h_{i+1})`` of successive runs (coarse to fine);
3. from the finest pair towards the coarse ones, the longest chain of local orders in which neighbours agree
   to ``tol`` relative (``|p_i - p_{i+1}| <= tol max(|p_i|, |p_{i+1}|)``) and are positive (the error falls);
4. an order is reported only for a chain of at least two local orders (three runs): the least-squares
   slope over that chain's runs. A single pair cannot show that it is asymptotic, so it gives no order.

What still passes: two pre-asymptotic local orders that happen to agree within ``tol``; a reference whose
error is larger than its bound says (the bound is its difference from a run at twice its step).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["asymptotic_order", "ORDER_TOL"]

#: relative agreement of successive local orders (B6's index-3 multipliers of Lobatto IIIA-2: 1.74, 2.03)
ORDER_TOL = 0.25


def _agree(a: float, b: float, tol: float) -> bool:
    return a > 0.0 and b > 0.0 and abs(a - b) <= tol * max(abs(a), abs(b))


def asymptotic_order(points, floor: float = 0.0, floor_factor: float = 10.0,
                     tol: float = ORDER_TOL) -> tuple[float | None, list[float]]:
    """The observed order of ``points = [(h, error), ...]`` from its asymptotic runs, and the local orders.

    Parameters
    ----------
    points : iterable of (float, float)
        Step (or tolerance) and error of each run; NaN errors (failed runs) are left out.
    floor : float
        The reference's error bound; runs with ``error <= floor_factor * floor`` are left out.
    floor_factor : float
    tol : float
        Relative agreement of neighbouring local orders.

    Returns
    -------
    order : float or None
        The least-squares slope of log error against log step over the finest chain of agreeing local
        orders (at least two), None when there is none.
    local : list of float
        The local orders of the runs that entered, coarse to fine (shown where no order is reported).
    """
    if not (math.isfinite(floor) and floor >= 0.0):
        raise ValueError(f"`floor` must be a finite non-negative error bound, got {floor!r}.")
    pts = sorted(((float(h), float(e)) for h, e in points
                  if math.isfinite(e) and e > 0.0 and e > floor_factor * floor), reverse=True)
    if len(pts) < 2:
        return None, []
    lh, le = np.log(np.array(pts)).T
    local = [float(x) for x in np.diff(le) / np.diff(lh)]
    last = len(local) - 1
    first = last
    while first > 0 and _agree(local[first - 1], local[first], tol):
        first -= 1
    if first == last:
        return None, local
    sel = slice(first, last + 2)
    return float(np.polyfit(lh[sel], le[sel], 1)[0]), local
