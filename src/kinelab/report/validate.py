"""``kinelab validate``: every kinelab computation against Pinocchio (and yourdfpy), on the bundled robots.

Each check measures a figure, compares it with a stated tolerance and records pass/fail. The report
is a list of :class:`Check` rows, printed as a table, written as Markdown/HTML/JSON with ``--out``.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab import ik
from kinelab.analysis import families, singular
from kinelab.analysis import oracles as checks
from kinelab.collision import CollisionError, Collisions, collision_model
from kinelab.dq import kinematics as bk
from kinelab.dq.algebra import DualQuat
from kinelab.errors import KinelabError
from kinelab.geometry import quat_wxyz_from_matrix
from kinelab.ik.analytic import redundancy
from kinelab.ik.analytic.classify import classify, general_class
from kinelab.ik.analytic.kernel import GENERAL_6R
from kinelab.ik.analytic.redundancy import has_swept_form, swept_arm
from kinelab.ik.branches import SAME
from kinelab.ik.limits import distance
from kinelab.ik.request import check_seed, make_request
from kinelab.ik.result import Branches
from kinelab.report.bench.collisions import FLOOR_AND_TABLE
from kinelab.report.bench.completeness import FOUND, own_configuration
from kinelab.report.check import SHARE, samples_for
from kinelab.report.check import Z95 as Z95  # re-exported: where the reports and their tests read them
from kinelab.report.check import Check as Check
from kinelab.report.check import wilson as wilson
from kinelab.report.closed_checks import CLOSED_CHECKS
from kinelab.report.provenance import provenance
from kinelab.report.wholebody_checks import WHOLE_CHECKS
from kinelab.robot import Chain, load
from kinelab.robot.tree import Robot
from kinelab.studies import paper000_era as ep
from kinelab.studies import paper001_stanford as seed001
from kinelab.studies import paper003_youbot as yb
from kinelab.values import is_whole

DEFAULT_ROBOTS = ("stanford", "era", "youbot", "panda", "ur5", "talos", "baxter", "fourbar", "delta",
                  "cassie")  # whole: the last five, the last three closing loops
DEFAULT_N = 200


@dataclass
class Report:
    """The checks of one ``kinelab validate`` run, with what it ran on."""
    checks: list[Check] = field(default_factory=list)
    robots: list[str] = field(default_factory=list)
    n: int = DEFAULT_N
    seed: int = 0
    provenance: dict = field(default_factory=provenance)

    @property
    def passed(self) -> bool:
        """True when every check passed."""
        return all(c.passed for c in self.checks)

    def to_dict(self) -> dict:
        """The JSON form (``kinelab validate --json``, report.json)."""
        return {
            "provenance": self.provenance,
            "passed": self.passed,
            "robots": self.robots,
            "n": self.n,
            "seed": self.seed,
            "versions": {"pinocchio": pin.__version__, "numpy": np.__version__},
            "checks": [{**asdict(c), "passed": c.passed, "interval_95": c.interval} for c in self.checks],
        }


def model_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """yourdfpy vs Pinocchio FK at n configurations; Pinocchio's Jacobians vs finite differences."""
    fk = checks.fk_vs_yourdfpy(robot, n, seed)
    jac = checks.jacobians_vs_fd(robot, max(10, n // 10), seed)
    cert = robot.fk_certificate
    return [
        Check(robot.name, "judge: compiled FK vs Pinocchio (certificate)",
              max(cert.max_position_error, cert.max_rotation_error), 1e-12, "m or rad",
              f"{cert.configurations} q incl. limits" if cert.certified else cert.reason),
        Check(robot.name, "FK position: yourdfpy vs Pinocchio", fk.max_position, 1e-9, "m", f"{n} random q"),
        Check(robot.name, "FK rotation: yourdfpy vs Pinocchio", fk.max_rotation, 1e-9, "rad", f"{n} random q"),
        Check(robot.name, "Jacobians (3 frames) vs central differences", jac.max_rotation, 1e-6, "",
              f"{jac.count} random q, max abs entry"),
    ]


def stanford_paper_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Seed 001: the tool rotation at the paper's target against the printed N (6 digits)."""
    oMtool = robot.fk(seed001.TARGET_Q)
    d = seed001.quat_distance_wxyz(quat_wxyz_from_matrix(oMtool.rotation), seed001.N_REAL_WXYZ)
    return [Check(robot.name, "seed 001: rotation at the paper's target vs printed N", d,
                  seed001.PRINTED_DIGITS_TOL, "", "quaternion components, up to sign")]


def biquaternion_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Λ(q) by the chain product and A(q) by screw transforms against Pinocchio."""
    worst_pose = worst_A = 0.0
    for q in robot.random_qs(max(10, n // 10), seed + 1):
        lam, ref = bk.pose(robot, q).as_array(), DualQuat.from_se3(robot.fk(q)).as_array()
        worst_pose = max(worst_pose, min(np.abs(lam - ref).max(), np.abs(lam + ref).max()))
        J = robot.jacobian_local(q)
        worst_A = max(worst_A, float(np.abs(bk.a_matrix(robot, q) - np.vstack([J[3:], J[:3]])).max()))
    count = max(10, n // 10)
    return [Check(robot.name, "biquaternion Λ(q) vs Pinocchio FK (up to ±)", worst_pose, 1e-12, "", f"{count} q"),
            Check(robot.name, "biquaternion A(q) vs Pinocchio LOCAL Jacobian", worst_A, 1e-10, "", f"{count} q")]


def solver_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """FRDM and the biquaternion solver on seeded reachable targets, every answer checked by Pinocchio."""
    rows = []
    for solver, allowed in (("frdm", 0.02), ("biquat", 0.05)):
        count = max(n // 4, samples_for(1 - allowed, SLACK))
        rng = np.random.default_rng(seed + 2)
        failures, times, iters, worst = 0, [], [], 0.0
        for k in range(count):
            target = robot.fk(robot.random_q(rng))
            # the paper's methods as published: FRDM without the Newton finish
            pure: dict[str, Any] = {"finish": "none"} if solver == "frdm" else {}
            res = ik.solve(robot, target, solver=solver, seed=k, time_budget=0.2, **pure)
            dp, dr = robot.tool_error(res.q, target)  # the check, independent of the solver's own
            ok = res.success and dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(res.q)
            failures += not ok
            times.append(res.wall_time)
            iters.append(res.iterations)
            worst = max(worst, dp if ok else 0.0)
        rows.append(Check(robot.name, f"{solver}: targets solved (Pinocchio-checked)", 1 - failures / count,
                          1 - allowed, SHARE, f"{count} targets, median {np.median(times) * 1e3:.2f} ms, median "
                          f"{np.median(iters):.0f} iterations, worst solved error {worst:.1e} m", at_least=True,
                          samples=count))
    return rows


def analytic_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Where the arm has a closed form: its branches confirmed by Pinocchio, and every FRDM, biquaternion and DLS
    answer from a random start is one of them (with the share of FRDM answers on the branch nearest the start)."""
    arm = classify(robot).arm or general_class(robot).arm
    if arm is None:
        return _swept_checks(robot, n, seed) + completeness_checks(robot, seed)
    form = "elimination" if arm.kind == GENERAL_6R else "1-D search" if arm.searched else "closed form"
    targets = _closed_form_targets(robot, n, seed)
    branches = [ik.solve_all(robot, t, solver="analytic") for t in targets]
    rows = [Check(robot.name, f"{form}: every branch met (Pinocchio-checked)", _worst(robot, targets, branches),
                  1e-6, "m or rad", f"{len(targets)} targets, {np.mean([len(b) for b in branches]):.2f} branches "
                  "each within the limits")]
    rows += [_on_branches(robot, solver, form, targets, branches, seed) for solver in ("frdm", "biquat", "dls")]
    return rows + completeness_checks(robot, seed)


def _on_branches(robot: Chain, solver: str, form: str, targets: list[pin.SE3], branches: list[Branches],
                 seed: int) -> Check:
    """How many of ``solver``'s answers from random starts lie off the closed form's branches (FRDM's detail: the
    share on the branch nearest its start)."""
    on_branch = nearest = solved = 0
    for k, start, res in _solved_from_random_starts(robot, targets, solver, seed):
        solved += 1
        gaps = [distance(robot, res.q, b.q) for b in branches[k]]
        on_branch += min(gaps) <= SAME  # answers met to 1e-6 lie up to ~2e-4 rad off a branch near a singularity
        nearest += int(np.argmin(gaps)) == int(np.argmin([distance(robot, start, b.q) for b in branches[k]]))
    detail = f"{solved} of {len(targets)} solved from random starts"
    if solver == "frdm" and solved:
        detail += f"; on the branch nearest its start in {100 * nearest / solved:.0f} %"
    return Check(robot.name, f"{solver}: answers off the {form}'s branches", float(solved - on_branch), 0.0, "count",
                 detail)


COMPLETENESS_POSES = 2000
COMPLETENESS_BAR = 0.995  # what 2,000 poses can show at 95 %: all found gives 99.81 % at least, 4 misses 99.52 %
SWEPT_BAR = 0.95  # answers on a swept branch (see _swept_checks)
SLACK = 2  # misses a share's sample is sized to allow while its 95 % lower bound still clears the bar


def completeness_checks(robot: Chain, seed: int) -> list[Check]:
    """Where the arm has every branch (a closed form or a 1-D search, at a held joint for a 7R arm): the share of
    COMPLETENESS_POSES seeded poses whose own configuration is among the branches Pinocchio confirms, its 95 %
    lower bound COMPLETENESS_BAR at least (a double root is met to the square root of rounding only: its misses
    are counted apart)."""
    if classify(robot).arm is None and general_class(robot).arm is None and not has_swept_form(robot):
        return []
    r = own_configuration(robot, COMPLETENESS_POSES, seed)
    return [Check(robot.name, f"completeness: the pose's own configuration among the branches, to {FOUND:g} rad",
                  r["found"], COMPLETENESS_BAR, SHARE, f"{r['method']}; {r['poses']} poses, {r['misses']} missed "
                  f"({r['near_misses']} at a double root), {r['branches_mean']:.2f} branches each within the limits "
                  f"(at most {r['branches_max']})", at_least=True, samples=r["poses"])]


def _swept_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """A 7R arm with a swept closed form (docs/analytic.md): its branches at 16 values of the held joint
    confirmed by Pinocchio, and every FRDM and DLS answer from a random start one of the branches at its own
    value of that joint, to SAME (95 % at least: an answer within the tolerances can sit at a limit whose exact
    root lies just beyond it, or near a singular shoulder several 1e-3 rad along the near-continuum)."""
    if not has_swept_form(robot):
        return []
    held = swept_arm(robot).joint
    form = "elimination" if swept_arm(robot).arm.kind == GENERAL_6R else "closed form"
    # a share's sample for the 95 % bar, and a tenth more for the targets a random start does not reach
    targets = _closed_form_targets(robot, n, seed, at_least=int(1.1 * samples_for(SWEPT_BAR, SLACK)) + 1)
    found = [ik.solve_all(robot, t, redundancy=16) for t in targets]
    rows = [Check(robot.name, f"{form}, joint {held + 1} swept: every branch met (Pinocchio-checked)",
                  _worst(robot, targets, found), 1e-6, "m or rad",
                  f"{len(targets)} targets, {np.mean([len(f) for f in found]):.1f} answers each at 16 samples")]
    req = make_request("frdm")
    for solver in ("frdm", "dls"):
        on_branch = solved = 0
        for k, _, res in _solved_from_random_starts(robot, targets, solver, seed):
            solved += 1
            branches = [a[0] for a in redundancy.at_value(robot, targets[k], req, float(res.q[held]))]
            on_branch += any(distance(robot, b, res.q) <= SAME for b in branches)
        rows.append(Check(robot.name, f"{solver}: every answer is a {form} branch at its own joint {held + 1}",
                          on_branch / max(solved, 1), SWEPT_BAR, SHARE,
                          f"{solved} of {len(targets)} solved from random starts", at_least=True, samples=solved))
    return rows


def _closed_form_targets(robot: Chain, n: int, seed: int, at_least: int = 10) -> list[Any]:
    """max(at_least, n / 4) seeded targets, the FK of random configurations (oMtool)."""
    rng = np.random.default_rng(seed + 5)
    return [robot.fk(robot.random_q(rng)) for _ in range(max(at_least, n // 4))]


def _worst(robot: Chain, targets: list[Any], answers: Sequence[Sequence[Any]]) -> float:
    """The largest position or rotation error [m or rad] (Pinocchio) of any answer against its target."""
    return max(max(robot.tool_error(a.q, t)) for t, found in zip(targets, answers, strict=True) for a in found)


def _solved_from_random_starts(robot: Chain, targets: list[Any], solver: str,
                               seed: int) -> list[tuple[int, np.ndarray, Any]]:
    """(target index, start, answer) of each target that ``solver`` solves from its seeded random start."""
    out = []
    for k, target in enumerate(targets):
        start = robot.random_q(np.random.default_rng(seed + 1000 + k))
        res = ik.solve(robot, target, solver=solver, q0=start, seed=k, time_budget=0.2)
        if res.success:
            out.append((k, start, res))
    return out


def collision_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Where the robot has collision geometry: the check (sphere, hull and exact tests) agrees with Pinocchio's
    distance computation on every pair, and no success of a solve with collisions= collides (a floor and a
    table around it)."""
    env = FLOOR_AND_TABLE
    try:
        model = collision_model(robot, Collisions(environment=env))
    except CollisionError:
        return []
    rng = np.random.default_rng(seed + 6)
    count = max(20, n)
    agree = 0
    for _ in range(count):
        q = robot.random_q(rng)
        found = model.colliding_pair(q) is not None
        pin.forwardKinematics(robot.model, model.data, robot.to_pin_q(q))
        pin.updateGeometryPlacements(robot.model, model.data, model.geom, model.gdata)
        pin.computeDistances(model.geom, model.gdata)
        closest = min(r.min_distance for r in model.gdata.distanceResults)
        agree += found == (closest <= model.margin)
    solved = clear = 0
    for k in range(max(10, n // 4)):
        q = robot.random_q(rng)
        if model.colliding_pair(q, first_test=False) is not None:
            continue
        res = ik.solve(robot, robot.fk(q), seed=k, collisions=env, time_budget=0.5)
        solved += res.success
        clear += res.success and model.contact(res.q, first_test=False) is None
    return [Check(robot.name, "collisions: configurations where the check and Pinocchio's distances disagree",
                  float(count - agree), 0.0, "count",
                  f"{count} random configurations, floor and table; {model.summary}"),
            Check(robot.name, "collisions: successes that collide", float(solved - clear), 0.0, "count",
                  f"{solved} targets solved clear of the floor and table")]


def seed001_run_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Seed 001's run: from the paper's start to its target with K = 1, h = 0.01 s."""
    run = seed001.reproduce(robot, record=True)
    dp, dr = robot.tool_error(run.q, robot.fk(seed001.TARGET_Q))
    m_start = float(np.linalg.norm(run.diagnostics.trajectory.M[0][1:4]))
    predicted = 0.01 * np.ceil(np.log(m_start / 5e-7) / -np.log(1 - 0.01))
    return [
        Check(robot.name, "seed 001: the paper's run reaches 1e-6 (position)", dp, 1e-6, "m",
              f"model time {run.diagnostics.model_time:.2f} s at K = 1 (paper: about 40 s)"),
        Check(robot.name, "seed 001: the paper's run reaches 1e-6 (rotation)", dr, 1e-6, "rad"),
        Check(robot.name, "seed 001: final M0 = -1 as in the paper", abs(run.diagnostics.M0 + 1.0), 1e-9, ""),
        Check(robot.name, "seed 001: model time vs closed-form prediction", abs(run.diagnostics.model_time - predicted),
              1e-9, "s", f"{predicted:.2f} s predicted"),
    ]


def youbot_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Seed 003: the paper's J and Pinocchio's rank at θ2 = θ3 = 0, the box, and the families of a sweep."""
    rng = np.random.default_rng(seed + 3)
    count = max(20, n // 5)
    sing = [yb.singular_configuration(rng) for _ in range(count)]
    off_paper = sum(yb.paper_rank(q) != 5 for q in sing)
    off_pin = sum(singular.analyze(robot, q).rank != 5 for q in sing)
    box = sum(yb.paper_rank(robot.random_q(rng)) != 6 for _ in range(count))
    J_fd = 0.0
    for _ in range(10):
        Q = robot.random_q(rng)
        fd = np.array([(yb.paper_location(Q + 1e-6 * e) - yb.paper_location(Q - 1e-6 * e)) / 2e-6 for e in np.eye(8)]).T
        J_fd = max(J_fd, float(np.abs(fd - yb.paper_jacobian(Q)).max()))
    sweep = families.sweep(robot, samples=max(2000, 10 * n), seed=seed, progress=False)
    texts = [" and ".join(r.text for r in f.relations) for f in sweep.families]
    found = "arm_joint_2 = 0 and arm_joint_3 = 0" in texts
    return [
        Check(robot.name, "seed 003: paper's J vs finite differences of X(Q)", J_fd, 1e-6, ""),
        Check(robot.name, "seed 003: Q at θ2 = θ3 = 0 where the paper's J is not of rank 5", float(off_paper), 0.0,
              "count", f"{count} Q"),
        Check(robot.name, "seed 003: Q at θ2 = θ3 = 0 where Pinocchio's SVD is not of rank 5", float(off_pin), 0.0,
              "count", f"{count} Q"),
        Check(robot.name, "seed 003: Q over the limit box where the paper's J is not of rank 6", float(box), 0.0,
              "count", f"{count} Q"),
        Check(robot.name, "seed 003: the sweep finds θ2 = θ3 = 0", 1.0 if found else 0.0, 1.0, "yes/no",
              "families: " + "; ".join(texts), at_least=True),
    ]


def era_checks(robot: Chain, n: int, seed: int) -> list[Check]:
    """Seed 000: the three ERA passages with and without the paper's bypass."""
    return _elbow_checks(robot, ep) + _lock_checks(robot, ep)


def _elbow_checks(robot: Chain, ep) -> list[Check]:
    passage = ep.elbow_passage(robot)
    run = ep.run(passage, robot)
    reach = ~passage.unreachable
    w, wo = run.with_bypass, run.without
    return [
        Check(robot.name, "seed 000 elbow, bypass: largest joint step between samples", w.max_joint_step, 0.25,
              "rad", f"without bypass {wo.max_joint_step:.3f} rad, {len(wo.events)} monitor events"),
        Check(robot.name, "seed 000 elbow, bypass: worst error on reachable samples",
              float(w.position_error[reach].max()), 1e-6, "m",
              f"without bypass {wo.position_error[reach].max():.2f} m, "
              f"reached {wo.reached[reach].sum()}/{reach.sum()}"),
        Check(robot.name, "seed 000 elbow, bypass: samples leaving the fold's quadrants",
              float(ep.quadrant_violations(w, passage)), 0.0, "count", f"{passage.samples} samples"),
    ]


def _lock_checks(robot: Chain, ep) -> list[Check]:
    """Passages 2 and 3: with the bypass the joint path closes every lap; without, the paper's drift."""
    checks = []
    for name, joints, bypass in (("wrist", (4, 6), "q5, q6 < 80°"), ("shoulder", (0, 6), "q1 frozen")):
        passage = ep.PASSAGES[name](robot)
        run = ep.run(passage, robot)
        w, wo = run.with_bypass, run.without
        laps_w = ep.lap_changes(w, passage)
        laps_wo = np.rad2deg(ep.lap_changes(wo, passage))
        a, b = joints
        drift = ", ".join(f"θ{j + 1} {np.array2string(laps_wo[:, j], precision=1)}°" for j in joints)
        if name == "wrist":  # q5 down and q7 up by the same amount, every lap
            shown = bool((laps_wo[:, a] < -5).all() and (laps_wo[:, b] > 5).all())
        else:  # q1 and q7 climbing together
            shown = bool((laps_wo[:2, a] > 60).all() and np.allclose(laps_wo[:, a], laps_wo[:, b], atol=1e-3))
        checks += [
            Check(robot.name, f"seed 000 {name}, {bypass}: largest joint step", w.max_joint_step, 0.05, "rad",
                  f"without bypass {wo.max_joint_step:.3f} rad"),
            Check(robot.name, f"seed 000 {name}, {bypass}: joint change over a lap (after the 1st)",
                  float(np.abs(laps_w[1:]).max()), 1e-5, "rad"),
            Check(robot.name, f"seed 000 {name}, {bypass}: worst tool error", float(w.position_error.max()), 1e-6,
                  "m", f"reached {w.reached.sum()}/{passage.samples}"),
            Check(robot.name, f"seed 000 {name}, without bypass: the paper's drift shows", 1.0 if shown else 0.0,
                  1.0, "yes/no", f"per-lap change {drift}", at_least=True),
        ]
    return checks


PAPER_CHECKS: dict[str, list[Callable[[Chain, int, int], list[Check]]]] = {
    "stanford": [stanford_paper_checks, seed001_run_checks],
    "youbot": [youbot_checks],
    "era": [era_checks],
}
GENERAL_CHECKS = [model_checks, biquaternion_checks, solver_checks, analytic_checks, collision_checks]


def _groups(robot: Chain | Robot) -> list[Any]:
    """The check groups a robot takes: a whole robot the whole-body checks, a chain the general ones and its
    paper's."""
    if isinstance(robot, Robot):
        return list(CLOSED_CHECKS if robot.closures else WHOLE_CHECKS)
    return [*GENERAL_CHECKS, *PAPER_CHECKS.get(robot.name, [])]


HEARTBEAT = 8.0  # [s] a line at least this often (under 10 s with a busy machine's delay)


@contextlib.contextmanager
def heartbeat(label: str | None) -> Iterator[None]:
    """While the block runs, a line on stderr every HEARTBEAT seconds saying what still runs (``label``; None:
    silent): a log or a pipe never waits long on a slow group without a word."""
    if label is None:
        yield
        return
    done, started = threading.Event(), time.perf_counter()

    def beat() -> None:
        while not done.wait(HEARTBEAT):
            print(f"{label}: still running ({time.perf_counter() - started:.0f} s)", file=sys.stderr, flush=True)

    thread = threading.Thread(target=beat, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()


def run(robots: list[str] | None = None, n: int | None = None, seed: int = 0, progress: bool = False,
        lines: bool = False) -> Report:
    """Run every check on ``robots`` (default: stanford, era, youbot, panda, ur5, the whole talos and baxter, and
    fourbar, delta and cassie, which close loops: a whole robot takes the whole-body checks,
    :mod:`kinelab.report.wholebody_checks`, one with loops :mod:`kinelab.report.closed_checks`)."""
    check_seed(seed)
    names = list(robots or DEFAULT_ROBOTS)
    n = DEFAULT_N if n is None else n
    if not is_whole(n, 1):
        raise KinelabError(f"validate needs n ≥ 1 configurations per check, got {n!r}")
    loaded = [load(name) for name in names]  # fail early, before any work, on a bad name
    report = Report(robots=names, n=n, seed=seed)
    steps = [(robot, fn) for robot in loaded for fn in _groups(robot)]
    for k, (robot, fn) in enumerate(tqdm(steps, desc="validate (check groups)", disable=not progress, unit="group")):
        started = time.perf_counter()
        label = f"validate {k + 1}/{len(steps)}: {robot.name}, {fn.__name__.replace('_', ' ')}"
        with heartbeat(label if lines else None):
            found = fn(robot, n, seed)
        report.checks.extend(found)
        if lines:  # a log or a pipe: one line per group as it ends, never silent for a whole run
            failed = sum(not c.passed for c in found)
            print(f"{label}: {len(found)} checks, {failed} failed ({time.perf_counter() - started:.1f} s)",
                  file=sys.stderr, flush=True)
    return report
