"""Colour scales that spread a field's values over the colours by area (no Qt, no VTK).

A distance from a vertex is small on most of a shape, so linear colours paint most of it
alike; the "spread" scale maps a value to the share of the area at or below it, so each
tenth of the colours covers about a tenth of the surface.
"""

from __future__ import annotations

import numpy as np

ROBUST_PERCENTILE = 99.0  # the robust range's end: this area-weighted percentile of |value|
SPREAD_SHARE = 0.25  # "auto" spreads where a tenth of the linear scale covers more area
TENTHS = 10
KNOTS = 64  # pieces of the piecewise-linear map from value to colour position
TICKS = (0.0, 0.25, 0.5, 0.75, 1.0)  # colour bar positions labelled on a spread scale


def crowded_share(values: np.ndarray, weights: np.ndarray, clim: tuple[float, float]) -> float:
    """The largest share (0..1) of the total weight whose values fall in one tenth of
    the linear scale ``clim`` (values beyond it counted at its ends)."""
    lo, hi = (float(x) for x in clim)
    if not hi > lo:
        return 1.0
    position = np.clip((np.asarray(values, dtype=np.float64) - lo) / (hi - lo), 0.0, 1.0)
    tenth = np.minimum((position * TENTHS).astype(int), TENTHS - 1)
    weights = np.asarray(weights, dtype=np.float64)
    return float(np.bincount(tenth, weights=weights, minlength=TENTHS).max() / weights.sum())


def spread_knots(values: np.ndarray, weights: np.ndarray, n: int = KNOTS):
    """(knot values, knot positions): the area-weighted quantiles of ``values`` at 0,
    1/n, ..., 1, a strictly increasing map to colour position (``np.interp(x, *knots)``);
    a value covering more than 1/n of the area keeps one knot, its lowest position."""
    values = np.asarray(values, dtype=np.float64)
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(np.asarray(weights, dtype=np.float64)[order])
    cumulative /= cumulative[-1]
    positions = np.linspace(0.0, 1.0, n + 1)
    at = np.searchsorted(cumulative, positions[1:-1])
    knots = np.concatenate([[values[order[0]]], values[order[np.minimum(at, len(order) - 1)]]])
    knots = np.append(knots, values[order[-1]])
    unique, first = np.unique(knots, return_index=True)
    if len(unique) < 2:  # one value everywhere
        return np.array([unique[0], unique[0] + 1.0]), np.array([0.0, 1.0])
    pos = positions[first]
    pos[[0, -1]] = 0.0, 1.0
    return unique, pos


def tick_values(knots) -> list[tuple[float, float]]:
    """(value, position) of the colour bar's ticks on the spread scale ``knots``."""
    values, positions = knots
    return [(float(np.interp(p, positions, values)), float(p)) for p in TICKS]


def auto_spread(values: np.ndarray, weights: np.ndarray):
    """The spread knots of non-negative ``values`` crowded into a tenth of the linear
    range (more than :data:`SPREAD_SHARE` of the weight), else None."""
    values = np.asarray(values, dtype=np.float64)
    if values.size == 0 or values.min() < 0:
        return None
    if crowded_share(values, weights, (0.0, float(values.max()))) <= SPREAD_SHARE:
        return None
    return spread_knots(values, weights)


def robust_limit(values: np.ndarray, weights: np.ndarray, percent: float = ROBUST_PERCENTILE):
    """The ``percent`` weighted percentile of |values|."""
    a = np.abs(np.asarray(values, dtype=np.float64))
    order = np.argsort(a, kind="stable")
    cumulative = np.cumsum(np.asarray(weights, dtype=np.float64)[order])
    i = int(np.searchsorted(cumulative, percent / 100.0 * cumulative[-1]))
    return float(a[order[min(i, len(a) - 1)]])
