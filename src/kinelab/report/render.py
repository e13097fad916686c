"""Every table and figure kinelab writes: the validate report and the bench figures.

Figures are drawn on ``matplotlib.figure.Figure`` objects, which need no pyplot state and no backend
choice, so rendering never changes the caller's matplotlib settings.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from kinelab.files import write_output
from kinelab.report.bench import loops, scaling, versus, wholebody
from kinelab.report.outfolder import atomic_folder
from kinelab.report.page import CAPTIONS, validate_html
from kinelab.report.provenance import LIBRARIES
from kinelab.report.validate import Report
from kinelab.studies import paper000_era as ep
from kinelab.studies import paper001_stanford as seed001


def validate_table(report: Report, width: int = 120) -> str:
    """The checks as a text table whose columns fit ``width`` characters (long check names wrap within their
    column), with a closing 'N passed, M failed' line."""
    robot_w = max(5, *(len(c.robot) for c in report.checks)) if report.checks else 5
    unit_w = max(6, *(1 + len(c.unit_shown) for c in report.checks))  # six, or the longest unit and a space
    fixed = robot_w + 2 + 2 + 10 + 2 + 12 + 1 + unit_w + 6  # the columns and gaps around the check name
    name_w = max(24, min(max((len(c.name) for c in report.checks), default=24), width - fixed))
    lines = [f"{'robot':<{robot_w}}  {'check':<{name_w}}  {'measured':>10}  {'limit':<12} {'unit':<{unit_w}}result"]
    for c in report.checks:
        wrapped = textwrap.wrap(c.name, name_w) or [""]
        lines.append(f"{c.robot:<{robot_w}}  {wrapped[0]:<{name_w}}  {c.measured:>10}  {c.limit:<12} "
                     f"{c.unit_shown:<{unit_w}}{'PASS' if c.passed else 'FAIL'}")
        lines += [f"{'':<{robot_w}}  {more}" for more in wrapped[1:]]
    failed = sum(not c.passed for c in report.checks)
    lines.append(f"{len(report.checks) - failed} passed, {failed} failed")
    return "\n".join(lines)


# each joint's curve drawn narrower and on top of the one before, so that curves which coincide (the elbow
# passage keeps θ3 = θ5) all stay visible: a wide pale band, a line, a dashed line
CURVE_STYLES: tuple[dict[str, Any], ...] = ({"linewidth": 6.0, "alpha": 0.4}, {"linewidth": 2.0},
                                             {"linewidth": 1.6, "linestyle": (0, (4, 2))})


def _passage_figure(run: Any, name: str, joints: tuple[int, ...], folder: Path) -> str:
    fig = Figure(figsize=(10, 3.2))
    axes = fig.subplots(1, 2, sharey=True)
    for ax, res, title in ((axes[0], run.without, f"ERA {name}, without bypass"),
                           (axes[1], run.with_bypass, f"ERA {name}, with bypass")):
        for j, style in zip(joints, CURVE_STYLES, strict=False):
            ax.plot(np.rad2deg(res.q[:, j]), label=f"θ{j + 1}", **style)
        ax.set_title(title)
        ax.set_xlabel("path sample")
    axes[0].set_ylabel("deg")
    axes[1].legend()
    fig.tight_layout()
    fig.savefig(folder / f"era_{name}.png", dpi=100)
    return f"era_{name}.png"


def validate_figures(report: Report, folder: Path) -> list[str]:
    """The report's figures as PNG files in ``folder`` (the ERA passages, seed-001 convergence)."""
    names = []
    if "era" in report.robots:
        for name, joints in (("elbow", (2, 3, 4)), ("wrist", (4, 6)), ("shoulder", (0, 6))):
            passage = ep.PASSAGES[name]()
            names.append(_passage_figure(ep.run(passage), name, joints, folder))
    if "stanford" in report.robots:
        traj = seed001.reproduce().diagnostics.trajectory
        fig = Figure(figsize=(5, 3.2))
        ax = fig.subplots()
        ax.semilogy(traj.t, np.linalg.norm(traj.M[:, 1:4], axis=1), label="|m⃗| (rotation part)")
        ax.semilogy(traj.t, np.linalg.norm(traj.M[:, 5:8], axis=1), label="|m0⃗| (moment part)")
        ax.set_xlabel("model time [s]")
        ax.set_title("seed 001: error biquaternion, K = 1")
        ax.legend()
        fig.tight_layout()
        fig.savefig(folder / "seed001_convergence.png", dpi=100)
        names.append("seed001_convergence.png")
    return names


def write_validate_report(report: Report, out: str | Path) -> Path:
    """Write report.json, report.md, report.html and the figures into the folder ``out`` (all or nothing)."""
    with atomic_folder(out, "validate") as folder:
        _write_validate_files(report, folder)
    return Path(out)


def provenance_line(p: dict[str, Any]) -> str:
    """What the run ran on, in one sentence (:func:`kinelab.report.provenance.provenance`)."""
    commit = f", commit {p['commit'][:12]}" if p.get("commit") else ""
    libraries = ", ".join(f"{name} {p[name]}" for name in LIBRARIES if name in p)
    cores = f", {p['cores']} cores" if p.get("cores") else ""
    return (f"Run {p['date']} with kinelab {p['kinelab']}{commit} (compiled core {p['core']}), {libraries}, "
            f"Python {p['python']}, on {p['processor']}{cores}; command: `{p['command']}`.")


def _write_validate_files(report: Report, folder: Path) -> None:
    figures = validate_figures(report, folder)
    write_output(folder / "report.json", json.dumps(report.to_dict(), indent=2))
    md = ["# kinelab validate", "", f"Robots: {', '.join(report.robots)}; n = {report.n} configurations for the FK "
          f"checks, each other check stating its own sample; seed = {report.seed}. Shares carry their 95 % Wilson "
          "interval and pass on its bound (a share ≥ its bar passes when the interval's lower end is).", "",
          provenance_line(report.provenance), "",
          "| robot | check | measured | limit | result |", "|---|---|---|---|---|"]
    md += [f"| {c.robot} | {c.name} | {' '.join(filter(None, (c.measured, c.unit_shown)))}{c.interval_shown} | "
           f"{c.limit} | {'PASS' if c.passed else 'FAIL'} |" for c in report.checks]
    complete = [c for c in report.checks if c.name.startswith("completeness")]
    if complete:
        md += ["", "## Completeness", "", "| robot | own configuration found | poses, misses, branches |",
               "|---|---|---|"]
        md += [f"| {c.robot} | {c.measured} | {c.detail} |" for c in complete]
    md += [""] + [f"![{CAPTIONS.get(name, name)}]({name})" for name in figures]
    write_output(folder / "report.md", "\n".join(md) + "\n")
    write_output(folder / "report.html", validate_html(report, {n: (folder / n).read_bytes() for n in figures}))


def bench_markdown(result: dict[str, Any]) -> str:
    """The bench rows as a Markdown table."""
    p = result["protocol"]
    lines = [f"Bench {result['date']}, {result['machine']['processor']}, Python {result['machine']['python']}; "
             f"n = {p['n']} targets per robot, seed {p['seed']}, best of {p.get('repeats', 1)} rounds per target, "
             f"budget {p['budget_s'] * 1e3:g} ms, "
             f"tolerances {p['tol_pos_m']:g} m / {p['tol_rot_rad']:g} rad (Pinocchio-checked).", "",
             "| robot | solver | success | median | p95 | median (solved) | iterations |",
             "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(f"| {r['robot']} | {r['solver']} | {r['success_pct']:.1f} % | {r['median_us']:.0f} µs | "
                     f"{r['p95_us']:.0f} µs | {r['median_solved_us']:.0f} µs | {r['median_iterations']:.0f} |")
    if result.get("not_run"):
        lines += ["", "Not run: " + "; ".join(f"{k} ({v})" for k, v in result["not_run"].items())]
    return "\n".join(lines)


def write_bench(result: dict[str, Any], out: str | Path) -> Path:
    """bench.json, bench.md and bench.png in the folder ``out`` (all or nothing)."""
    with atomic_folder(out, "bench") as folder:
        _write_bench_files(result, folder)
    return Path(out)


def _write_bench_files(result: dict[str, Any], folder: Path) -> None:
    write_output(folder / "bench.json", json.dumps(result, indent=2))
    sections = [bench_markdown(result)] if "rows" in result else []
    if "scaling" in result:
        sections.append(scaling.markdown(result["scaling"]))
    if "tracking" in result:
        sections.append(ep.tracking_markdown(result["tracking"]))
    if "loops" in result:
        sections.append(loops.markdown(result["loops"]["throughput"], result["loops"]["tracking"],
                                       result["loops"]["budgets"]))
    if "budgets" in result:
        sections.append(loops.budget_markdown(result["budgets"]))
    if "whole_body" in result:
        sections.append(wholebody.markdown(result["whole_body"]))
    if "closed" in result:
        from kinelab.report.bench import closed_step  # the loop bench's module only where it ran

        sections.append(closed_step.markdown(result["closed"]))
    if "collisions_step" in result:
        from kinelab.report.bench import collision_step  # the collision bench's module only where it ran

        sections.append(collision_step.markdown(result["collisions_step"]))
    if "versus" in result:
        sections.append(versus.markdown(result["versus"]))
    write_output(folder / "bench.md", "\n\n".join(sections) + "\n")
    if "rows" in result:
        bench_figure(result, folder / "bench.png")


def _bars(axes: tuple[Any, Any], robots: list[str], by: dict[str, dict[str, Any]], offset: float, width: float,
          label: str) -> None:
    """One solver's bars: success [%] on the first axes, median time [µs] on the second, a bar per robot (0 where
    the solver has no row for it)."""
    xs = [i + offset for i in range(len(robots))]
    axes[0].bar(xs, [by.get(rb, {}).get("success_pct", 0) for rb in robots], width, label=label)
    axes[1].bar(xs, [by.get(rb, {}).get("median_us", 0) for rb in robots], width, label=label)


def bench_figure(result: dict[str, Any], path: str | Path) -> None:
    """Success rate and median time per solver and robot, as a PNG."""
    rows = result["rows"]
    robots = list(dict.fromkeys(r["robot"] for r in rows))
    solvers = list(dict.fromkeys(r["solver"] for r in rows))
    fig = Figure(figsize=(11, 4))
    ax1, ax2 = fig.subplots(1, 2)
    width = 0.8 / max(len(solvers), 1)
    for k, s in enumerate(solvers):
        _bars((ax1, ax2), robots, {r["robot"]: r for r in rows if r["solver"] == s}, k * width, width, s)
    for ax, title in ((ax1, "success [%]"), (ax2, "median time [µs]")):
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(robots))], robots)
        ax.set_title(title)
    ax2.set_yscale("log")
    ax1.set_ylim(0, 105)
    handles, labels = ax1.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(solvers), fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=110)
