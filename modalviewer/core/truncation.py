"""How much of a signature a truncated spectrum misses (the modes beyond lambda_k).

The modes are M-orthonormal, so the signature's area-weighted total over the surface is
``Z(t) = sum_j exp(-lambda_j t)`` and the share the missing modes hold,
``E(t) = tail(t) / (Z_k(t) + tail(t))`` with ``tail(t) = sum_{j>k} exp(-lambda_j t)``,
depends on the eigenvalues alone.  The missing eigenvalues are extrapolated by a power
law ``lambda_j ~ j^p`` (Weyl's law: ``p = 1`` for a surface's Laplacian) fitted on the
upper half of the computed non-zero ones, its exponent lowered by ``SAFETY_EXPONENT``;
the tail is bounded by its integral (incomplete gamma function) and doubled
(``SAFETY_FACTOR``): an upper-bound-style estimate of the whole surface's share, not a
proof; at one vertex :func:`~.local_signature.local_signature` gives the exact value.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.special as ss

from .spectrum import Spectrum

TRUNCATION_LEVEL = 0.05
"""The estimated truncation error above which the viewer warns and suggests a k."""
SAFETY_FACTOR = 2.0
SAFETY_EXPONENT = 0.8
MIN_EXPONENT = 0.25
MAX_EXPONENT = 2.0


def _law(spec: Spectrum) -> tuple[np.ndarray, float, int]:
    """(non-zero eigenvalues (k,), exponent p, number of non-zero modes of the mesh)."""
    zero = spec.zero_mode_mask()
    lam = np.maximum(np.asarray(spec.eigenvalues, dtype=np.float64)[~zero], 0.0)
    if lam.size == 0:
        raise ValueError("the spectrum has no non-zero modes; compute more modes")
    per = 3 if spec.is_vector else 1
    unknowns = spec.n_vertices * per - int(zero.sum())
    k = lam.size
    fitted = 1.0  # Weyl's law where there are too few eigenvalues to fit
    if k >= 4:  # fitted on the upper half
        h = k // 2
        j = np.arange(h + 1, k + 1)
        fitted = float(np.polyfit(np.log(j), np.log(np.maximum(lam[h:], 1e-300)), 1)[0])
    p = float(np.clip(SAFETY_EXPONENT * fitted, MIN_EXPONENT, MAX_EXPONENT))
    return lam, p, max(unknowns, k)


def _tail(lam_k: float, k: int, p: float, first: float, last: float, times) -> np.ndarray:
    """(T,) ``integral_first^last exp(-t lambda_k (x/k)^p) dx`` for each t."""
    times = np.asarray(times, dtype=np.float64)
    if last <= first:
        return np.zeros_like(times)
    a = np.maximum(times * lam_k, 1e-300)
    s = 1.0 / p
    lo = ss.gammaincc(s, a * (first / k) ** p)
    hi = ss.gammaincc(s, a * (last / k) ** p)
    return (k / p) * a ** (-s) * ss.gamma(s) * np.maximum(lo - hi, 0.0)


def truncation_error(spec: Spectrum, times: float | Sequence[float] | np.ndarray) -> np.ndarray:
    """(T,) estimated share (0..1) of the signature (zero modes left out) at each of the
    positive scales ``times`` that the modes beyond the spectrum's hold."""
    lam, p, total = _law(spec)
    times = np.atleast_1d(np.asarray(times, dtype=np.float64))
    k = lam.size
    z = np.exp(-np.outer(lam, times)).sum(axis=0)
    tail = SAFETY_FACTOR * _tail(float(lam[-1]), k, p, k, total, times)
    # at large scales both sums underflow to 0; the tail, which decays like exp(-lam_k t)
    # against the lowest mode's exp(-lam_1 t), is then nothing beside them
    whole = z + tail
    return np.divide(tail, whole, out=np.zeros_like(whole), where=whole > 0)


def k_for_truncation(spec: Spectrum, t: float, level: float = TRUNCATION_LEVEL) -> int:
    """The number of modes (zero modes included, at least the spectrum's own k, at most
    the mesh's unknowns) whose estimated truncation error (:func:`truncation_error`) at
    scale ``t`` is at most ``level``."""
    lam, p, total = _law(spec)
    k = lam.size
    zeros = spec.k - k
    t = float(t)
    if truncation_error(spec, [t])[0] <= level:
        return spec.k
    z = float(np.exp(-lam * t).sum())
    lam_k = float(lam[-1])

    def error(m: float) -> float:
        known = z + _tail(lam_k, k, p, k, m, [t])[0]
        tail = SAFETY_FACTOR * _tail(lam_k, k, p, m, total, [t])[0]
        return tail / (known + tail)

    lo, hi = float(k), float(total)
    if error(hi) > level:
        return total + zeros
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if error(mid) > level:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1.0:
            break
    return int(min(np.ceil(hi), total)) + zeros
