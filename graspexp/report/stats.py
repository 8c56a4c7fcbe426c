"""Small statistics for success rates and timings: the Wilson score interval, a rate with its interval in
%, and percentiles."""

import math
from collections.abc import Iterable

import numpy as np

Z_95 = 1.959963984540054
"""Two-sided 95 % standard-normal quantile (the inverse normal CDF at 0.975)."""


def wilson_interval(successes: int, trials: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval for a binomial proportion, as fractions in [0, 1].

    ``p = k/n``, ``centre = (p + z^2/(2n)) / (1 + z^2/n)``,
    ``half = z / (1 + z^2/n) * sqrt(p(1-p)/n + z^2/(4n^2))``. Unlike the normal (Wald) interval it
    stays inside [0, 1] and is not degenerate at 0/n or n/n, which matters with 10 trials.
    ``trials == 0`` gives (nan, nan).
    """
    k, n = int(successes), int(trials)
    if n < 0 or not 0 <= k <= max(n, 0):
        raise ValueError(f"need 0 <= successes <= trials, got {k}/{n}")
    if n == 0:
        return (math.nan, math.nan)
    p = k / n
    z2 = z * z
    denom = 1.0 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z / denom * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n))
    lo, hi = centre - half, centre + half
    # exact ends: at k = 0 the lower bound is 0, at k = n the upper bound is 1 (rounding aside)
    return (0.0 if k == 0 else max(0.0, lo), 1.0 if k == n else min(1.0, hi))


def success_pct(successes: int, trials: int) -> tuple[float, float, float]:
    """``(rate, lo, hi)`` in %: the success rate of ``successes`` in ``trials`` and its Wilson 95 % interval
    (:func:`wilson_interval`); nan for each when ``trials == 0``."""
    lo, hi = wilson_interval(successes, trials)
    return (100.0 * successes / trials if trials else math.nan, 100.0 * lo, 100.0 * hi)


def percentiles(values: Iterable[float], qs: tuple[float, ...] = (50, 95)) -> tuple[float, ...]:
    """Percentiles (numpy's linear interpolation) of the finite values; nan for each when none."""
    arr = np.asarray([v for v in values if v is not None], dtype=float)
    arr = arr[np.isfinite(arr)]
    if arr.size == 0:
        return tuple(math.nan for _ in qs)
    return tuple(float(v) for v in np.percentile(arr, qs))
