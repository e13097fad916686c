"""``report.html`` of ``kinelab validate``: one self-contained, styled page.

The verdict and a summary come first, then one section per source (the models and solvers, and each seed
paper) with its checks (failures highlighted) and its captioned figures, then the machine and the versions.
Figures are embedded as data URIs, so the page opens anywhere without its folder.
"""

from __future__ import annotations

import base64
import html
import platform

from kinelab.report.check import Check
from kinelab.report.provenance import LIBRARIES
from kinelab.report.validate import Report

CAPTIONS = {
    "era_elbow.png": "Seed 000, ERA elbow passage: joint angles θ3–θ5 along the path without the bypass (left: the "
                     "elbow folds the wrong way at the stretched configuration) and with the paper's kick (right). "
                     "θ3 and θ5 stay equal along the passage: θ3 is the wide pale band under θ5's dashed line.",
    "era_wrist.png": "Seed 000, ERA wrist passage: θ5 and θ7 lap after lap without the bypass (left: they drift "
                     "apart, the paper's spinning) and with q5, q6 < 80° held (right: every lap closes).",
    "era_shoulder.png": "Seed 000, ERA shoulder passage: θ1 and θ7 without the bypass (left: they climb together) "
                        "and with q1 frozen (right).",
    "seed001_convergence.png": "Seed 001, Stanford arm: the rotation part |m⃗| and the moment part |m0⃗| of the error "
                               "biquaternion against model time, law (9) with K = 1, h = 0.01 s.",
}
SECTIONS = (
    ("seed 000", "Seed paper 000 — FRDM on the European Robotic Arm (Danilov)", "era_"),
    ("seed 001", "Seed paper 001 — biquaternion control of the Stanford arm (Lomovtseva & Chelnokov)", "seed001"),
    ("seed 003", "Seed paper 003 — singular configurations of the KUKA youBot (Kapustina)", "seed003"),
    ("completeness", "Completeness — every branch: each pose's own configuration among its branches", "-"),
)
STYLE = """
body{font:15px/1.5 system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#1d1d1f}
h1{margin-bottom:.2em} h2{margin-top:2em;border-bottom:1px solid #ddd;padding-bottom:.2em}
.verdict{padding:.8em 1.2em;border-radius:8px;font-size:1.2em;font-weight:600;color:#fff}
.pass{background:#1e7d32} .fail{background:#b3261e}
table{border-collapse:collapse;width:100%;margin:.8em 0;font-size:14px}
th,td{border-bottom:1px solid #e4e4e4;padding:.35em .6em;text-align:left;vertical-align:top}
th{background:#f4f4f6} td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
tr.failed td{background:#fdecea} td.ok{color:#1e7d32;font-weight:600} td.bad{color:#b3261e;font-weight:700}
.detail{color:#666;font-size:12px} figure{margin:1.2em 0} figure img{max-width:100%;border:1px solid #ddd}
figcaption{color:#444;font-size:13px;margin-top:.3em} .meta{color:#555;font-size:13px}
"""


def validate_html(report: Report, figures: dict[str, bytes]) -> str:
    """The whole page for ``report``, its figures (file name → PNG bytes) embedded."""
    verdict = "PASS" if report.passed else "FAIL"
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>kinelab validate: {verdict}</title>",
             f"<style>{STYLE}</style></head><body><h1>kinelab validate</h1>",
             f"<div class='verdict {verdict.lower()}'>{verdict}</div><p>{html.escape(_summary(report))}</p>",
             _machine(report.provenance)]
    return "".join(parts) + _sections(report.checks, figures) + "</body></html>"


def _sections(checks: list[Check], figures: dict[str, bytes]) -> str:
    """The general checks' section, then one section per SECTIONS entry that has checks, with its figures."""
    general = [c for c in checks if not any(c.name.startswith(key) for key, _, _ in SECTIONS)]
    parts = [_section("Models and solvers, checked against Pinocchio", general, {})]
    for key, title, prefix in SECTIONS:
        mine = [c for c in checks if c.name.startswith(key)]
        if mine:
            parts.append(_section(title, mine, {n: b for n, b in figures.items() if n.startswith(prefix)}))
    return "".join(parts)


def _summary(report: Report) -> str:
    """The page's opening sentence: how many checks passed on which robots, and the failed ones named."""
    failed = [c for c in report.checks if not c.passed]
    summary = (f"{len(report.checks) - len(failed)} of {len(report.checks)} checks passed on "
               f"{', '.join(report.robots)} ({report.n} configurations for the FK checks, each other check its own "
               f"sample; shares with their 95 % Wilson interval, passing on its bound; seed {report.seed}).")
    if failed:
        summary += " Failed: " + "; ".join(f"{c.robot}: {c.name}" for c in failed) + "."
    return summary


def _section(title: str, checks: list[Check], figures: dict[str, bytes]) -> str:
    rows = "".join(
        f"<tr class='{'' if c.passed else 'failed'}'><td>{html.escape(c.robot)}</td><td>{html.escape(c.name)}"
        + (f"<div class='detail'>{html.escape(c.detail)}</div>" if c.detail else "")
        + f"</td><td class='num'>{html.escape(c.measured)} {html.escape(c.unit_shown)}"
        f"{html.escape(c.interval_shown)}</td>"
        f"<td class='num'>{html.escape(c.limit)}</td>"
        f"<td class='{'ok' if c.passed else 'bad'}'>{'PASS' if c.passed else 'FAIL'}</td></tr>"
        for c in checks)
    table = ("<table><tr><th>robot</th><th>check</th><th>measured</th><th>limit</th><th>result</th></tr>"
             f"{rows}</table>") if checks else ""
    figs = "".join(
        f"<figure><img alt='{html.escape(name)}' src='data:image/png;base64,{base64.b64encode(data).decode()}'>"
        f"<figcaption>Figure: {html.escape(CAPTIONS.get(name, name))}</figcaption></figure>"
        for name, data in figures.items())
    return f"<h2>{html.escape(title)}</h2>{table}{figs}"


def _machine(p: dict) -> str:
    """What the run ran on (:func:`kinelab.report.provenance.provenance`), as a table."""
    rows = {"date (UTC)": p["date"], "command": p["command"], "kinelab": p["kinelab"],
            "commit": p.get("commit") or "not a git checkout", "compiled core": p["core"],
            "machine": f"{platform.platform()} ({platform.machine()})", "processor": p["processor"],
            "logical processors": str(p.get("cores", "?")), "Python": p["python"],
            **{name: str(p[name]) for name in LIBRARIES if name in p}}
    items = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in rows.items())
    return f"<h2>Machine and versions</h2><table class='meta'>{items}</table>"
