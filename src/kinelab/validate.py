"""``kinelab validate``: every kinelab computation against Pinocchio (and yourdfpy), on the bundled robots.

Each check measures a figure, compares it with a stated tolerance and records pass/fail. The report
is a list of :class:`Check` rows, printed as a table, written as Markdown/HTML/JSON with ``--out``.
"""

from __future__ import annotations

import html
import json
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab import checks
from kinelab.robot import Robot, load
from kinelab.studies import stanford_seed001 as seed001

DEFAULT_ROBOTS = ("stanford", "era", "youbot", "panda", "ur5")
DEFAULT_N = 200


@dataclass(frozen=True)
class Check:
    """One validated figure: ``value`` must be ≤ ``tolerance`` (both in ``unit``)."""

    robot: str
    name: str
    value: float
    tolerance: float
    unit: str
    detail: str = ""

    @property
    def passed(self) -> bool:
        return bool(np.isfinite(self.value) and self.value <= self.tolerance)


@dataclass
class Report:
    checks: list[Check] = field(default_factory=list)
    robots: list[str] = field(default_factory=list)
    n: int = DEFAULT_N
    seed: int = 0

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def to_dict(self) -> dict:
        return {
            "passed": self.passed,
            "robots": self.robots,
            "n": self.n,
            "seed": self.seed,
            "versions": {"pinocchio": pin.__version__, "numpy": np.__version__},
            "checks": [{**asdict(c), "passed": c.passed} for c in self.checks],
        }


def model_checks(robot: Robot, n: int, seed: int) -> list[Check]:
    """yourdfpy vs Pinocchio FK at n configurations; Pinocchio's Jacobians vs finite differences."""
    fk = checks.fk_vs_yourdfpy(robot, n, seed)
    jac = checks.jacobians_vs_fd(robot, max(10, n // 10), seed)
    return [
        Check(robot.name, "FK position: yourdfpy vs Pinocchio", fk.max_position, 1e-9, "m", f"{n} random q"),
        Check(robot.name, "FK rotation: yourdfpy vs Pinocchio", fk.max_rotation, 1e-9, "rad", f"{n} random q"),
        Check(robot.name, "Jacobians (3 frames) vs central differences", jac.max_rotation, 1e-6, "",
              f"{jac.count} random q, max abs entry"),
    ]


def stanford_paper_checks(robot: Robot, n: int, seed: int) -> list[Check]:
    """Seed 001: the tool rotation at the paper's target against the printed N (6 digits)."""
    oMtool = robot.fk(seed001.TARGET_Q)
    quat = pin.Quaternion(oMtool.rotation)
    d = seed001.quat_distance_wxyz([quat.w, quat.x, quat.y, quat.z], seed001.N_REAL_WXYZ)
    return [Check(robot.name, "seed 001: rotation at the paper's target vs printed N", d,
                  seed001.PRINTED_DIGITS_TOL, "", "quaternion components, up to sign")]


PAPER_CHECKS: dict[str, list[Callable[[Robot, int, int], list[Check]]]] = {
    "stanford": [stanford_paper_checks],
}


def run(robots=None, n: int | None = None, seed: int = 0, progress: bool = True) -> Report:
    """Run every check on ``robots`` (default: stanford, era, youbot, panda, ur5)."""
    names = list(robots or DEFAULT_ROBOTS)
    n = n or DEFAULT_N
    loaded = [load(name) for name in names]  # fail early, before any work, on a bad name
    report = Report(robots=names, n=n, seed=seed)
    steps = [(robot, fn) for robot in loaded for fn in [model_checks, *PAPER_CHECKS.get(robot.name, [])]]
    for robot, fn in tqdm(steps, desc="validate", disable=not progress, unit="check"):
        report.checks.extend(fn(robot, n, seed))
    return report


def format_table(report: Report) -> str:
    lines = [f"{'robot':<10} {'check':<56} {'measured':>10} {'tolerance':>10}  result"]
    for c in report.checks:
        unit = f" {c.unit}" if c.unit else ""
        lines.append(f"{c.robot:<10} {c.name:<56} {c.value:>10.2e} {c.tolerance:>10.0e}{unit:<4} "
                     f"{'PASS' if c.passed else 'FAIL'}")
    failed = sum(not c.passed for c in report.checks)
    lines.append(f"{len(report.checks) - failed} passed, {failed} failed")
    return "\n".join(lines)


def write_report(report: Report, out: str | Path) -> Path:
    """Write report.json, report.md and report.html into the folder ``out``."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "report.json").write_text(json.dumps(report.to_dict(), indent=2))
    md = ["# kinelab validate", "", f"Robots: {', '.join(report.robots)}; n = {report.n}; seed = {report.seed}.", "",
          "| robot | check | measured | tolerance | result |", "|---|---|---|---|---|"]
    md += [f"| {c.robot} | {c.name} | {c.value:.2e} {c.unit} | {c.tolerance:.0e} | {'PASS' if c.passed else 'FAIL'} |"
           for c in report.checks]
    (folder / "report.md").write_text("\n".join(md) + "\n")
    rows = "".join(
        f"<tr><td>{html.escape(c.robot)}</td><td>{html.escape(c.name)}</td><td>{c.value:.2e} {c.unit}</td>"
        f"<td>{c.tolerance:.0e}</td><td>{'PASS' if c.passed else 'FAIL'}</td></tr>"
        for c in report.checks
    )
    (folder / "report.html").write_text(
        "<!doctype html><meta charset='utf-8'><title>kinelab validate</title>"
        f"<h1>kinelab validate: {'PASS' if report.passed else 'FAIL'}</h1>"
        "<table border=1><tr><th>robot</th><th>check</th><th>measured</th><th>tolerance</th><th>result</th></tr>"
        f"{rows}</table>"
    )
    return folder
