"""The step's compiled path (:mod:`kinelab.core._body`): the robot's tree packed once and certified against
Pinocchio, the tasks' structure packed once per structure, the targets set per call.

A robot's tree serves only once certified: at CERTIFY_SAMPLES seeded configurations its joint placements, the
Jacobians of every body frame, its centre of mass and Jacobian, and its integration equal Pinocchio's within
CERTIFY_TOL; a tree with a joint of another kind (spherical, planar, ...) or a failed certificate is served by the
readable step (:mod:`kinelab.wholebody.step`), which gives the same answers. DAQP's C interface is taken from the
installed module (its version checked); another version, or none, leaves the readable path.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.core import _body
from kinelab.robot.tree import Robot
from kinelab.wholebody.qp import Outcome as Outcome  # the step's flags, read as cp.Outcome
from kinelab.wholebody.step import StepResult
from kinelab.wholebody.tasks import Task

CERTIFY_SAMPLES = 20
CERTIFY_TOL = 1e-10  # [m, rad] compiled against Pinocchio
DAQP_VERSIONS = ("0.11.",)  # the C interface's layout these declarations match
REVOLUTE, PRISMATIC, CONTINUOUS, FREEFLYER, MIMIC_REVOLUTE, MIMIC_PRISMATIC = range(6)


def daqp_linked() -> bool:
    """True once DAQP's C functions are taken from the installed module (a supported version), else False."""
    if _body.daqp_ready():
        return True
    import ctypes
    import importlib.metadata  # 20 ms: read when the step is first taken, not when a chain's solve loads

    try:
        import daqp

        if not importlib.metadata.version("daqp").startswith(DAQP_VERSIONS):
            return False
        lib = ctypes.CDLL(daqp.__file__)
        quadprog = ctypes.cast(lib.daqp_quadprog, ctypes.c_void_p).value
        defaults = ctypes.cast(lib.daqp_default_settings, ctypes.c_void_p).value
    except (ImportError, OSError, AttributeError, importlib.metadata.PackageNotFoundError):
        return False
    if not quadprog or not defaults:
        return False
    _body.set_daqp(quadprog, defaults)
    return True


def _joint(model: pin.Model, jid: int) -> tuple[int, np.ndarray, float, float] | None:
    """(kind, unit axis in the joint's frame, ratio, offset) of joint jid, or None for a kind not compiled."""
    jm = model.joints[jid]
    short = jm.shortname()
    if short == "JointModelFreeFlyer":
        return FREEFLYER, np.zeros(3), 1.0, 0.0
    if short == "JointModelMimic":
        inner = jm.extract()
        ratio, offset = float(inner.scaling), float(inner.offset)
        prismatic, axis = _motion_axis(model, jm, ratio or 1.0)
        return (MIMIC_PRISMATIC if prismatic else MIMIC_REVOLUTE), axis, ratio, offset
    if jm.nv != 1:
        return None
    prismatic, axis = _motion_axis(model, jm, 1.0)
    kind = CONTINUOUS if jm.nq == 2 else PRISMATIC if prismatic else REVOLUTE
    return kind, axis, 1.0, 0.0


def _motion_axis(model: pin.Model, jm: pin.JointModel, scale: float) -> tuple[bool, np.ndarray]:
    """(prismatic, unit axis in the joint's frame) of a one-velocity joint's motion subspace at the neutral q
    (divided by ``scale``: a mimic joint's ratio). A continuous joint is a rotation."""
    data = jm.createData()
    jm.calc(data, pin.neutral(model))
    S = np.asarray(data.S, dtype=float).ravel() / scale
    prismatic = jm.nq != 2 and bool(np.linalg.norm(S[3:]) < 0.5 * np.linalg.norm(S))
    axis = S[:3] if prismatic else S[3:]
    return prismatic, axis / np.linalg.norm(axis)


def _pose(M: pin.SE3) -> np.ndarray:
    return np.concatenate([M.rotation.ravel(), M.translation])


def pack_tree(robot: Robot) -> _body.Tree | None:
    """The robot's tree for the compiled step, or None (a joint kind not compiled, or the certificate failed)."""
    tree = build_tree(robot)
    return tree if tree is not None and certified(robot, tree) else None


def build_tree(robot: Robot) -> _body.Tree | None:
    """A new compiled tree of the robot (its own buffers), not certified: another copy of a certified one (a
    thread's), or None (a joint kind not compiled)."""
    model = robot.model
    nj = model.njoints - 1
    parent, kind = np.zeros(nj + 1, dtype=np.intc), np.zeros(nj + 1, dtype=np.intc)
    iq, iv = np.zeros(nj + 1, dtype=np.intc), np.zeros(nj + 1, dtype=np.intc)
    ratio, offset, mass = np.ones(nj + 1), np.zeros(nj + 1), np.zeros(nj + 1)
    place, axis, lever = np.zeros((nj + 1, 12)), np.zeros((nj + 1, 3)), np.zeros((nj + 1, 3))
    for j in range(1, nj + 1):
        found = _joint(model, j)
        if found is None:
            return None
        kind[j], axis[j], ratio[j], offset[j] = found
        parent[j], iq[j], iv[j] = model.parents[j], model.joints[j].idx_q, model.joints[j].idx_v
        place[j] = _pose(model.jointPlacements[j])
        mass[j], lever[j] = model.inertias[j].mass, model.inertias[j].lever
    qlo, qhi = np.array(robot.lower, dtype=float), np.array(robot.upper, dtype=float)  # writable copies
    return _body.Tree(parent, kind, iq, iv, ratio, offset, place, axis, mass, lever, model.nq, model.nv, qlo, qhi)


def certified(robot: Robot, tree: _body.Tree) -> bool:
    """The compiled tree's placements, body-frame Jacobians, centre of mass and integration equal Pinocchio's at
    CERTIFY_SAMPLES seeded configurations (CERTIFY_TOL)."""
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(20261205)
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY][:40]
    for _ in range(CERTIFY_SAMPLES):
        q, v = robot.random_q(rng), rng.normal(size=model.nv)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        placed = tree.forward_placements(q)
        worst = max(np.abs(placed[j] - _pose(data.oMi[j])).max() for j in range(1, model.njoints))
        for fid in bodies:
            f = model.frames[fid]
            pose, J = tree.frame_jacobian(q, f.parentJoint, _pose(f.placement))
            ref = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            worst = max(worst, np.abs(pose - _pose(data.oMf[fid])).max(), np.abs(J - ref).max())
        if robot.mass > 0:
            c, Jc = tree.center_of_mass(q)
            worst = max(worst, np.abs(c - pin.centerOfMass(model, data, q)).max(),
                        np.abs(Jc - pin.jacobianCenterOfMass(model, data, q)).max())
        moved = tree.integrated(q, v, 0.01)
        worst = max(worst, np.abs(pin.difference(model, pin.integrate(model, q, 0.01 * v), moved)).max())
        if not worst <= CERTIFY_TOL:
            return False
    return True


@dataclass(frozen=True)
class StepProblem:
    """A task list as the compiled step takes it, one record of named arrays (``_body.Step(tree, problem)``): per
    weighted task (frames, relative frames, the centre of mass) its kind code, joint, root joint, axis (a centre
    of mass's coordinates as bits), priority, placements [R row-major, t], weights and gain; the posture's
    reference, weights, gain and priority (0: none); each level's damping per velocity; the couplings' q and v
    indices, ratios and offsets; and each one's slot in the list (for its error)."""

    kind: np.ndarray
    joint: np.ndarray
    root: np.ndarray
    axis: np.ndarray
    priority: np.ndarray
    place: np.ndarray
    root_place: np.ndarray
    wp: np.ndarray
    wo: np.ndarray
    gain: np.ndarray
    slot: np.ndarray
    post_ref: np.ndarray
    post_w: np.ndarray
    post_gain: float
    post_priority: int
    post_slot: int
    damping1: np.ndarray
    damping2: np.ndarray
    cq: np.ndarray
    cv: np.ndarray
    lq: np.ndarray
    lv: np.ndarray
    cratio: np.ndarray
    coffset: np.ndarray
    cslot: np.ndarray


class Packer:
    """What each task's :meth:`~kinelab.wholebody.tasks.Task.pack` hands over, collected into a
    :class:`StepProblem`. A list the compiled step does not take (two postures, a posture on the free-flyer) is
    ``refused`` with the reason, and the readable step answers it."""

    def __init__(self, robot: Robot):
        self.robot, self.index, self.refused = robot, 0, ""
        self.blocks: list[tuple[Any, ...]] = []  # per weighted task: kind, joint, root, axis, priority, ...
        self.slots: list[int] = []  # the list index of each weighted task
        self.post: tuple[np.ndarray, float, int, int] | None = None  # weights, gain, priority, slot
        self.diagonal = [np.zeros(robot.nv), np.zeros(robot.nv)]  # each level's damping per velocity
        self.couplings: list[tuple[int, int, int, int, float, float, int]] = []

    def weighted(self, task: Any, kind: int, joint: int, placement: pin.SE3 | None, axis: int, root: int = 0,
                 root_placement: pin.SE3 | None = None) -> None:
        """A weighted task's block: its kind code, the joint carrying its frame (and the root's), the frame's
        placement on it, its axis code."""
        place = np.zeros(12) if placement is None else _pose(placement)
        other = np.zeros(12) if root_placement is None else _pose(root_placement)
        self.blocks.append((kind, joint, root, axis, task.priority, place, other, task.weight,
                            float(getattr(task, "orientation_weight", 0.0) or 0.0), task.gain))
        self.slots.append(self.index)

    def posture(self, task: Any, weights: np.ndarray) -> None:
        """The one posture (its reference set per call)."""
        if self.post is not None or task.base:
            self.refused = "a second posture, or a posture on the free-flyer"
        self.post = (weights, task.gain, task.priority, self.index)

    def damping(self, task: Any, weights: np.ndarray) -> None:
        """A damping's diagonal, at its level."""
        self.diagonal[task.priority - 1] += weights

    def coupling(self, task: Any, qj: int, vj: int, ql: int, vl: int) -> None:
        """A coupling's indices, ratio and offset."""
        self.couplings.append((qj, vj, ql, vl, task.ratio, task.offset, self.index))

    def decline(self, reason: str) -> None:
        """A task the compiled step has no block for (a user's own): the readable step answers the list."""
        self.refused = reason

    def problem(self) -> StepProblem:
        """The record the compiled step is built from."""
        b = list(zip(*self.blocks, strict=True)) if self.blocks else [()] * 10
        ints = lambda values: np.array(values, dtype=np.intc)  # noqa: E731
        c = list(zip(*self.couplings, strict=True)) if self.couplings else [()] * 7
        weights, post_gain, post_priority, post_slot = self.post or (np.zeros(self.robot.nv), 0.0, 0, -1)
        return StepProblem(ints(b[0]), ints(b[1]), ints(b[2]), ints(b[3]), ints(b[4]),
                           np.array(b[5], dtype=float).reshape(-1, 12), np.array(b[6], dtype=float).reshape(-1, 12),
                           np.array(b[7], dtype=float), np.array(b[8], dtype=float), np.array(b[9], dtype=float),
                           ints(self.slots), self.robot.neutral(), np.array(weights, dtype=float), post_gain,
                           post_priority, post_slot, self.diagonal[0], self.diagonal[1], ints(c[0]), ints(c[1]),
                           ints(c[2]), ints(c[3]), np.array(c[4], dtype=float), np.array(c[5], dtype=float),
                           ints(c[6]))


@dataclass
class Packed:
    """A task list's compiled problem: the Step, its record, and the slots each task's target is written to per
    call (:meth:`~kinelab.wholebody.tasks.Task.refresh` calls :meth:`set_pose`, :meth:`set_point`,
    :meth:`set_posture`)."""

    step: _body.Step
    problem: StepProblem
    slots: tuple[int, ...]  # per task of the list: its weighted slot, or -1
    labels: tuple[str, ...]  # each task's label, in order

    def set_pose(self, slot: int, H: np.ndarray) -> None:
        """A weighted task's target pose (4 × 4)."""
        self.step.set_pose(slot, H)

    def set_point(self, slot: int, p: np.ndarray) -> None:
        """A weighted task's target point [m]."""
        self.step.set_point(slot, p)

    def set_posture(self, q_ref: np.ndarray, weights: np.ndarray | None) -> None:
        """The posture's reference (and per-velocity weights when they are set per call)."""
        self.problem.post_ref[:] = q_ref
        if weights is not None:
            self.problem.post_w[:] = weights


def structure(tasks: tuple[Task, ...]) -> tuple[Any, ...]:
    """The key of a task list's compiled problem: each task's :meth:`~kinelab.wholebody.tasks.Task.shape`
    (everything but the targets and the posture's reference)."""
    return tuple(t.shape() for t in tasks)


def pack(robot: Robot, tree: _body.Tree, tasks: tuple[Task, ...]) -> Packed | None:
    """The compiled problem of a task list, each task packing its own block; None where the compiled step does not
    take the list (the readable step answers it)."""
    packer = Packer(robot)
    for i, task in enumerate(tasks):
        packer.index = i
        task.pack(packer, robot)
    if packer.refused:
        return None
    problem = packer.problem()
    slots = [-1] * len(tasks)
    for k, i in enumerate(packer.slots):
        slots[i] = k
    return Packed(_body.Step(tree, problem), problem, tuple(slots), tuple(t.label for t in tasks))


def set_targets(robot: Robot, packed: Packed, tasks: tuple[Task, ...]) -> None:
    """Each task's target (and the posture's reference) written into the packed problem."""
    for task, slot in zip(tasks, packed.slots, strict=True):
        task.refresh(packed, robot, slot)


NOT_A_CONFIGURATION, SOLVED, SOLVED_SOFT = (int(Outcome.NOT_A_CONFIGURATION), int(Outcome.SOLVED),
                                             int(Outcome.SOLVED_SOFT))  # plain ints: read on every step
NO_LIMIT = np.empty(0)


def packed_for(robot: Robot, tasks: tuple[Task, ...], solver: str) -> Packed | None:
    """The compiled problem of the tasks, or None where the compiled step does not serve (a QP solver other than
    DAQP, DAQP not linked, a tree or a task it has no code for)."""
    if solver != "daqp" or not daqp_linked():
        return None
    tree = robot.derived("compiled tree", pack_tree)
    return None if tree is None else pack(robot, tree, tasks)


def run(packed: Packed, robot: Robot, q: np.ndarray, dt: float, bounds: tuple[np.ndarray, bool, np.ndarray],
        prev: np.ndarray | None, damping: float) -> StepResult | None:
    """One compiled step from q (nq contiguous float64 numbers) with the targets packed: the readable step's answer,
    or None for a q it leaves the readable step to check and name.

    Args:
        packed: the problem (:func:`packed_for`, its targets set).
        robot: its robot.
        q: the start (Pinocchio's q).
        dt: the step [s].
        bounds: (the velocity bounds (nv), whether positions are held, the acceleration bounds (nv, or empty)).
        prev: the velocity before the step (nv), or None.
        damping: the QP's damping.
    """
    vmax, position, amax = bounds
    q_out, v_out, errors = np.empty(robot.nq), np.empty(robot.nv), np.zeros((len(packed.labels), 2))
    returning = np.empty(robot.nv, dtype=np.uint8)
    flag, iterations = packed.step.step(q, dt, vmax, position, amax, NO_LIMIT if prev is None else prev, damping,
                                        q_out, v_out, errors, returning)
    if flag == NOT_A_CONFIGURATION:
        return None
    solved = flag == SOLVED or flag == SOLVED_SOFT  # the usual answer read without making an Outcome
    return StepResult(v_out, q_out, "solved" if solved else Outcome(flag).words, solved, errors,
                      returning.view(bool), iterations, packed.labels, robot.space.names_v)
