"""One validated figure of ``kinelab validate`` (:class:`Check`) and the interval of a share (Wilson's)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Check:
    """One validated figure: ``value`` must be ≤ ``tolerance`` (both in ``unit``), or ≥ it when ``at_least``;
    a check with ``unit == "yes/no"`` holds when ``value`` is 1 (yes)."""

    robot: str
    name: str
    value: float
    tolerance: float
    unit: str
    detail: str = ""
    at_least: bool = False
    samples: int | None = None  # the trials a share ("%") counts over: its 95 % interval is Wilson's

    @property
    def passed(self) -> bool:
        """True when the measured value is within the limit."""
        if not np.isfinite(self.value):
            return False
        return bool(self.value >= self.tolerance if self.at_least else self.value <= self.tolerance)

    @property
    def measured(self) -> str:
        """The value as shown: yes/no, a share in %, or a number."""
        if self.unit == "yes/no":
            return "yes" if self.value >= 1 else "no"
        return f"{100 * self.value:.1f} %" if self.unit == "%" else f"{self.value:.2e}"

    @property
    def unit_shown(self) -> str:
        """The unit as the reports show it: none for yes/no and shares, which say theirs."""
        return "" if self.unit in ("yes/no", "%") else self.unit

    @property
    def interval(self) -> tuple[float, float] | None:
        """The share's 95 % Wilson score interval (``unit`` "%" with ``samples``), else None."""
        if self.unit != "%" or not self.samples:
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
        shown = f"{100 * self.tolerance:g} %" if self.unit == "%" else f"{self.tolerance:.3g}"
        return ("≥ " if self.at_least else "≤ ") + shown


Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile


def wilson(share: float, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a share observed in n trials (95 % by default): (low, high), each in [0, 1]."""
    scale = 1.0 + z * z / n
    centre = (share + z * z / (2 * n)) / scale
    half = z * np.sqrt(share * (1.0 - share) / n + z * z / (4 * n * n)) / scale
    return max(0.0, float(centre - half)), min(1.0, float(centre + half))
