"""Inverse reachability of a mobile manipulator: from which platform positions (x, y) does the robot reach
a grasp, and with which heading? For each position of an x–y grid around the grasp, the robot with its
platform's x and y held there (the heading and the arm free: six coordinates on the youBot, against the
six components of the grasp) is asked for the grasp, every answer checked by Pinocchio; the reachable
positions are ranked by the arm's manipulability there. (A grid over the heading as well would ask a
5-joint arm for a full pose from a fixed platform, which it meets only by chance.)

The heading and the arm are a 6R chain; where it is in a closed-form class (the youBot's: heading ∥ joint 1,
joints 2, 3, 4 parallel; docs/analytic.md) every branch of every position comes from the closed form in one
batch and the position keeps its best-conditioned branch; otherwise a seeded numeric batch with restarts finds
one answer per position.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinelab.analysis.singular import conditioning_batch
from kinelab.errors import KinelabError, OptionError
from kinelab.ik.analytic.batch import all_branches_batch
from kinelab.ik.analytic.classify import classify
from kinelab.ik.api import solve_batch
from kinelab.ik.request import check_seed
from kinelab.ik.targets import as_target, reach_bound
from kinelab.robot import Chain, load
from kinelab.values import is_real, is_whole

PLATFORM = ("platform_x", "platform_y", "platform_yaw")

MAX_POSITIONS = 1_000_000  # platform positions of a base map's x-y grid


@dataclass(frozen=True)
class BaseMap:
    """Candidate platform poses and what the arm can do from each.

    Attributes:
        poses: (P, 3) platform x [m], y [m], yaw [rad] in the world frame.
        reachable: (P,) the arm reaches the grasp from there (Pinocchio-checked, within the limits).
        manipulability: (P,) Yoshikawa measure of the arm's Jacobian (linear rows / L) at the answer; 0 where
            not reachable.
        q: (P, n_arm) the arm's answer [rad] (NaN where not reachable).
    """

    poses: np.ndarray
    reachable: np.ndarray
    manipulability: np.ndarray
    q: np.ndarray

    def ranked(self, count: int = 10) -> np.ndarray:
        """Indices of the best ``count`` reachable poses, highest manipulability first.

        Raises:
            OptionError: ``count`` is not an integer ≥ 0 (a negative count once listed the unreachable poses).
        """
        check_count(count)
        order = np.argsort(-np.where(self.reachable, self.manipulability, -1.0))
        return order[: min(count, int(self.reachable.sum()))]


def check_count(count: object) -> None:
    """Refuse a count of best poses that is not an integer ≥ 0 (a negative one once listed the unreachable poses).

    Raises:
        OptionError: naming the value and what is valid.
    """
    if not is_whole(count, 0):
        raise OptionError("count", count, "an integer ≥ 0: how many of the best poses (kinelab map base --top)")


def base_map(robot: Chain, grasp: pin.SE3, step: float = 0.05, restarts: int = 10, seed: int = 0) -> BaseMap:
    """The platform poses from which ``robot`` (a mobile manipulator whose first joints are the platform's x,
    y and yaw) reaches ``grasp`` (oMgrasp, world frame).

    Args:
        robot: the whole robot (the youBot: its platform joints PLATFORM, then the arm).
        grasp: the tool pose to reach [m, world frame].
        step: spacing of the x–y grid [m], over the disc the arm can reach the grasp from.
        restarts: random restarts per candidate position.
        seed: base seed.

    Raises:
        KinelabError: a robot without the platform joints, or a bad step.
    """
    _check_base_map(robot, step, restarts, seed)
    grasp = as_target(grasp)
    turning = load(str(robot.source), tool=robot.tool, base=robot.base, locked={j: 0.0 for j in PLATFORM[:2]})
    xy = _platform_positions(turning, grasp, step)
    targets = np.array([(pin.SE3(np.eye(3), np.array([-x, -y, 0.0])) * grasp).homogeneous for x, y in xy])
    if classify(turning).arm is not None:
        success, answers, manip = _best_branches(turning, targets)
    else:
        success, answers, manip = _multistart(turning, targets, seed, restarts)
    yaw = np.where(success, answers[:, 0], np.nan)
    q = np.where(success[:, None], answers[:, 1:], np.nan)
    return BaseMap(np.column_stack([xy, yaw]), success, manip, q)


def _check_base_map(robot: Chain, step: object, restarts: object, seed: object) -> None:
    """The robot has the platform joints and a file to reload, the step is a number > 0 [m], the seed and the
    restarts integers ≥ 0.

    Raises:
        KinelabError: naming what is wrong.
    """
    missing = [j for j in PLATFORM if j not in robot.joint_names]
    if missing:
        raise KinelabError(f"{robot.name} has no platform joint {missing[0]!r}: a base map needs joints "
                           f"{', '.join(PLATFORM)}")
    if not is_real(step, 0, above=True):
        raise KinelabError(f"a base map needs a grid step > 0 [m], got {step!r}")
    check_seed(seed)
    check_seed(restarts, "restarts")
    if robot.source is None:
        raise KinelabError(f"{robot.name} was made from an in-memory model: a base map reloads it from its file")


def _platform_positions(turning: Chain, grasp: pin.SE3, step: float) -> np.ndarray:
    """(P, 2) the platform positions [m, world frame] on a grid of ``step`` over the disc around the grasp the arm
    can reach it from, refused before the grid is built when over MAX_POSITIONS.

    Raises:
        KinelabError: a grid of more than MAX_POSITIONS positions.
    """
    anchor, radius = reach_bound(turning)
    reach_xy = radius + float(np.hypot(anchor[0], anchor[1]))
    if (2 * reach_xy / step + 1) ** 2 > MAX_POSITIONS:
        raise KinelabError(f"a {step:g} m step over the {reach_xy:.3g} m the arm reaches is about "
                           f"{(2 * reach_xy / step) ** 2:.3g} platform positions, over {MAX_POSITIONS}; take a "
                           "larger step")
    ticks = np.arange(-np.ceil(reach_xy / step), np.ceil(reach_xy / step) + 1) * step
    return np.array([(grasp.translation[0] + a, grasp.translation[1] + b) for a in ticks for b in ticks
                     if np.hypot(a, b) <= reach_xy])


def _multistart(turning: Chain, targets: np.ndarray, seed: int, restarts: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(reached, one answer per target (P, n), its manipulability) from the seeded multistart's batch."""
    res = solve_batch(turning, targets, seed=seed, max_restarts=restarts)
    success, manip = res.success.copy(), np.zeros(len(targets))
    if success.any():
        manip[success] = _manipulability(turning, res.q[success])
    return success, res.q, manip


def _manipulability(turning: Chain, q: np.ndarray) -> np.ndarray:
    """Yoshikawa's measure of the arm's columns of the Jacobian (linear rows / L) at each row of q."""
    J = turning.jacobian_batch(q, frame="local_world_aligned")[:, :, 1:]  # the arm's columns
    return np.asarray(conditioning_batch(J, turning.characteristic_length())[0])


def _best_branches(turning: Chain, targets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(reached, the best-conditioned branch (P, 6), its manipulability) per target from the closed form's batch
    (every branch confirmed by Pinocchio)."""
    batch = all_branches_batch(turning, targets)
    success = batch.count > 0
    answers = np.full((len(targets), turning.n), np.nan)
    manip = np.zeros(len(targets))
    pose, row = np.nonzero(np.arange(batch.q.shape[1])[None, :] < batch.count[:, None])
    if pose.size:
        scores = _manipulability(turning, batch.q[pose, row])
        order = np.lexsort((scores, pose))  # by position, best branch last
        last = np.r_[pose[order][1:] != pose[order][:-1], True]
        best = order[last]
        answers[pose[best]] = batch.q[pose[best], row[best]]
        manip[pose[best]] = scores[best]
    return success, answers, manip
