"""Checks of the arguments at the public API's edge: counts, vertex indices, scales.

One place for the rules, so that every function rejects the same inputs with the same
words: counts are integers (not bools) of at least a minimum, vertex indices integers
in ``0..n-1`` (no negative ones), scales positive and finite.  Wrong types raise
TypeError, wrong values ValueError, indices out of range IndexError.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def _shown(value: object) -> str:
    """``value`` as the message shows it: numpy scalars as Python ones, long reprs cut."""
    if isinstance(value, np.generic):
        value = value.item()
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_integer(value: object) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, (int, np.integer)):
        return True
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iu"


def check_count(value: object, name: str, minimum: int = 1) -> int:
    """``value`` as an int, if it is an integer (Python or numpy, not bool) >= ``minimum``."""
    if not _is_integer(value):
        raise TypeError(f"{name} must be an integer, got {_shown(value)}")
    count = int(value)  # type: ignore[call-overload]
    if count < minimum:
        raise ValueError(f"{name} must be at least {minimum}, got {count}")
    return count


def _range_error(name: str, index: int, n: int) -> IndexError:
    what = "1 vertex" if n == 1 else f"{n} vertices"
    return IndexError(f"{name} {index} out of range: the mesh has {what} (0..{n - 1})")


def check_vertex(value: object, n: int, name: str = "vertex") -> int:
    """``value`` as an int, if it is an integer index in ``0..n-1``."""
    if not _is_integer(value):
        raise TypeError(f"{name} must be an integer index, got {_shown(value)}")
    index = int(value)  # type: ignore[call-overload]
    if not 0 <= index < n:
        raise _range_error(name, index, n)
    return index


def check_vertices(
    values: object, n: int, name: str = "vertices", allow_empty: bool = False
) -> np.ndarray:
    """(p,) int64 indices from one index or a sequence of them, each in ``0..n-1``."""
    idx = np.atleast_1d(np.asarray(values))  # a string: one element of kind "U" or "S"
    if idx.ndim != 1 or (idx.size == 0 and not allow_empty):
        raise ValueError(f"{name} must be one vertex index or a non-empty list of them")
    if idx.size and idx.dtype.kind not in "iu":
        raise TypeError(f"{name} must be integer vertex indices, got {_shown(values)}")
    idx = idx.astype(np.int64)
    bad = idx[(idx < 0) | (idx >= n)]
    if bad.size:
        raise _range_error(f"{name}: vertex", int(bad[0]), n)
    return idx


def check_times(values: object, name: str = "times") -> np.ndarray:
    """(T,) float64 scales from one scale or a 1-D sequence, all positive and finite."""
    if isinstance(values, (str, bytes)):
        raise TypeError(f"{name} must be numbers, got {_shown(values)}")
    try:
        times = np.atleast_1d(np.asarray(values, dtype=np.float64))
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be numbers, got {_shown(values)}") from None
    if times.ndim != 1 or times.size == 0:
        raise ValueError(f"{name} must be one scale or a non-empty 1-D sequence of them")
    bad = times[~(np.isfinite(times) & (times > 0))]
    if bad.size:
        raise ValueError(f"{name} must be positive and finite, got {_shown(float(bad[0]))}")
    return times


def check_t_range(
    t_range: Sequence[float] | np.ndarray, name: str = "t_range"
) -> tuple[float, float]:
    """``(t1, t2)`` as floats, positive and finite with ``0 < t1 < t2``."""
    if isinstance(t_range, (str, bytes)) or np.ndim(t_range) != 1 or len(t_range) != 2:
        raise TypeError(f"{name} must be a pair (t1, t2), got {_shown(t_range)}")
    t1, t2 = check_times(t_range, name)
    if not t1 < t2:
        raise ValueError(f"the scale range needs 0 < t1 < t2, got {name}=({t1:g}, {t2:g})")
    return float(t1), float(t2)
