"""One validated figure of ``kinelab validate`` (:class:`Check`), the interval of a share (Wilson's) and the
sample a share's bar needs.

A share (``unit`` "share": a fraction in [0, 1], shown in %) with its sample passes on its 95 % Wilson lower
bound, not on its point estimate: 50 successes in 50 show 92.9 % at least, which does not clear a 98 % bar. A
check that allows no failure counts its failures instead (``unit`` "count", at most 0)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SHARE = "share"  # a fraction in [0, 1], shown in %


@dataclass(frozen=True)
class Check:
    """One validated figure: ``value`` must be ≤ ``tolerance`` (both in ``unit``), or ≥ it when ``at_least``;
    a check with ``unit == "yes/no"`` holds when ``value`` is 1 (yes); a share (``unit == "share"``, a fraction)
    with ``samples`` holds when its 95 % Wilson bound on the bar's side clears the bar."""

    robot: str
    name: str
    value: float
    tolerance: float
    unit: str
    detail: str = ""
    at_least: bool = False
    samples: int | None = None  # the trials a share counts over: its 95 % interval is Wilson's

    @property
    def passed(self) -> bool:
        """True when the measured value is within the limit (a share's 95 % bound on the bar's side, where it has
        its sample)."""
        if not np.isfinite(self.value):
            return False
        low, high = self.interval or (self.value, self.value)
        return bool(low >= self.tolerance if self.at_least else high <= self.tolerance)

    @property
    def measured(self) -> str:
        """The value as shown: yes/no, a share in %, or a number."""
        if self.unit == "yes/no":
            return "yes" if self.value >= 1 else "no"
        if self.unit == "count":
            return f"{self.value:.0f}"
        return f"{100 * self.value:.1f} %" if self.unit == SHARE else f"{self.value:.2e}"

    @property
    def unit_shown(self) -> str:
        """The unit as the reports show it: none for yes/no and shares, which say theirs."""
        return "" if self.unit in ("yes/no", SHARE) else self.unit

    @property
    def interval(self) -> tuple[float, float] | None:
        """The share's 95 % Wilson score interval (``unit`` "share" with ``samples``), else None."""
        if self.unit != SHARE or not self.samples:
            return None
        return wilson(self.value, self.samples)

    @property
    def interval_shown(self) -> str:
        """The share's 95 % interval and sample as the reports show it (" (95 %: lo–hi %, n = N)"), else ""."""
        if self.interval is None:
            return ""
        low, high = self.interval
        return f" (95 %: {100 * low:.1f}–{100 * high:.1f} %, n = {self.samples})"

    @property
    def limit(self) -> str:
        """The tolerance as shown, with ≤ or ≥."""
        if self.unit == "yes/no":
            return "yes"
        shown = f"{100 * self.tolerance:g} %" if self.unit == SHARE else f"{self.tolerance:.3g}"
        return ("≥ " if self.at_least else "≤ ") + shown


Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile


def wilson(share: float, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a share observed in n trials (95 % by default): (low, high), each in [0, 1]."""
    scale = 1.0 + z * z / n
    centre = (share + z * z / (2 * n)) / scale
    half = z * np.sqrt(share * (1.0 - share) / n + z * z / (4 * n * n)) / scale
    return max(0.0, float(centre - half)), min(1.0, float(centre + half))


def samples_for(bar: float, failures: int = 0) -> int:
    """The smallest sample whose 95 % Wilson lower bound clears ``bar`` (a fraction) with ``failures`` misses."""
    n = failures + 1
    while wilson((n - failures) / n, n)[0] < bar:
        n += 1
    return n
