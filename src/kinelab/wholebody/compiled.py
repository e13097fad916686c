"""The step's compiled path (:mod:`kinelab.core._body`): the robot's tree packed once and certified against
Pinocchio, the tasks' structure packed once per structure, the targets set per call.

A robot's tree serves only once certified: at CERTIFY_SAMPLES seeded configurations its joint placements, the
Jacobians of every body frame, its centre of mass and Jacobian, and its integration equal Pinocchio's within
CERTIFY_TOL; a tree with a joint of another kind (spherical, planar, ...) or a failed certificate is served by the
readable step (:mod:`kinelab.wholebody.step`), which gives the same answers. DAQP's C interface is taken from the
installed module (its version checked); another version, or none, leaves the readable path.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from kinelab.core import _body
from kinelab.robot.tree import Robot
from kinelab.wholebody import evaluate as ev
from kinelab.wholebody.tasks import ComTask, CouplingTask, FrameTask, PostureTask, RelativeFrameTask, Task

CERTIFY_SAMPLES = 20
CERTIFY_TOL = 1e-10  # [m, rad] compiled against Pinocchio
DAQP_VERSIONS = ("0.11.",)  # the C interface's layout these declarations match
KINDS = {"pose": 0, "position": 1, "orientation": 2, "axis": 3}
T_RELATIVE, T_COM = 4, 5
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
    tree = _body.Tree(parent, kind, iq, iv, ratio, offset, place, axis, mass, lever, model.nq, model.nv, qlo, qhi)
    return tree if certified(robot, tree) else None


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


@dataclass
class Packed:
    """A task list's compiled problem: the Step and, per task, what to copy into it each call."""

    step: _body.Step
    targets: tuple[int, ...]  # indices of the tasks whose target is set per call (frames, relative, CoM)
    posture: int  # index of the posture task, or -1
    post_ref: np.ndarray  # the posture's reference, which the Step reads (written per call)
    post_w: np.ndarray  # the posture's weight per velocity, which the Step reads (written per call)
    labels: tuple[str, ...]  # each task's label, in order
    current: Any = None  # the ids of the task objects whose targets the Step holds


def structure(tasks: tuple[Task, ...]) -> tuple[Any, ...] | None:
    """The key of a task list's compiled problem (everything but the targets and the posture's reference: each
    task's :meth:`shape`), or None where the compiled step does not take it (more than one posture, a posture on
    the free-flyer)."""
    key = tuple(t.shape() for t in tasks)
    postures = [k for k in key if k[0] == "p"]
    if len(postures) > 1 or any(k[-1] for k in postures):
        return None
    return key


def pack(robot: Robot, tree: _body.Tree, tasks: tuple[Task, ...]) -> Packed:
    """The compiled problem of a task list (see :func:`structure`)."""
    kinds = _Kinds.of(tasks)
    post, couplings = kinds.posture, kinds.couplings
    post_w = np.zeros(robot.nv) if post is None else ev.posture_weight(robot, post)
    post_ref = robot.neutral()
    step = _body.Step(tree, *_weighted_rows(robot, kinds.weighted), post_ref, post_w, *_posture_terms(post),
                      *_coupling_indices(robot, couplings), np.array([c.ratio for c in couplings]),
                      np.array([c.offset for c in couplings]), np.array(kinds.targets, dtype=np.intc),
                      kinds.posture_index, np.array(kinds.coupling_index, dtype=np.intc))
    return Packed(step, kinds.targets, kinds.posture_index, post_ref, post_w, tuple(t.label for t in tasks))


@dataclass
class _Kinds:
    """A task list sorted by what the compiled step does with each: the weighted tasks (frames, relative frames,
    the CoM: their targets set per call), the posture (one at most) and the couplings, with their places in the
    list."""

    weighted: list[FrameTask | RelativeFrameTask | ComTask] = field(default_factory=list)
    targets: tuple[int, ...] = ()
    posture: PostureTask | None = None
    posture_index: int = -1
    couplings: list[CouplingTask] = field(default_factory=list)
    coupling_index: list[int] = field(default_factory=list)

    @classmethod
    def of(cls, tasks: tuple[Task, ...]) -> _Kinds:
        kinds = cls()
        for i, t in enumerate(tasks):
            if isinstance(t, PostureTask):
                kinds.posture, kinds.posture_index = t, i
            elif isinstance(t, CouplingTask):
                kinds.couplings.append(t)
                kinds.coupling_index.append(i)
            else:
                kinds.weighted.append(t)
                kinds.targets += (i,)
        return kinds


def _posture_terms(post: PostureTask | None) -> tuple[float, int]:
    """The posture's gain and priority for the compiled step (0, 0: no posture)."""
    return (0.0, 0) if post is None else (post.gain, post.priority)


Rows = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
             np.ndarray, np.ndarray]


def _weighted_rows(robot: Robot, weighted: list[FrameTask | RelativeFrameTask | ComTask]) -> Rows:
    """The compiled step's arrays of the weighted tasks (frames and the CoM), one entry per task: kind, joint,
    root joint, axis (or the CoM's component bits), priority, placement, root placement, position weight,
    orientation weight, gain."""
    n = len(weighted)
    kind, joint, root = np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc)
    axis, priority = np.zeros(n, dtype=np.intc), np.ones(n, dtype=np.intc)
    place, root_place = np.zeros((n, 12)), np.zeros((n, 12))
    wp, wo, gain = np.zeros(n), np.zeros(n), np.zeros(n)
    for k, t in enumerate(weighted):
        priority[k], gain[k], wp[k] = t.priority, t.gain, t.weight
        if isinstance(t, ComTask):
            kind[k], axis[k] = T_COM, sum(1 << i for i in t.index)
            continue
        frame = robot.model.frames[robot.frame_id(t.frame)]
        joint[k], place[k], wo[k] = frame.parentJoint, _pose(frame.placement), float(t.orientation_weight or 0.0)
        if isinstance(t, RelativeFrameTask):
            other = robot.model.frames[robot.frame_id(t.root)]
            kind[k], root[k], root_place[k] = T_RELATIVE, other.parentJoint, _pose(other.placement)
        else:
            kind[k], axis[k] = KINDS[t.task], "xyz".index(t.axis)
    return kind, joint, root, axis, priority, place, root_place, wp, wo, gain


def _coupling_indices(robot: Robot,
                      couplings: list[CouplingTask]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each coupled joint's and its leader's q and velocity indices: (joint q, joint v, leader q, leader v)."""
    ids = [[robot.model.joints[robot.model.getJointId(n)] for n in (c.joint, c.leader)] for c in couplings]
    return (np.array([a.idx_q for a, _ in ids], dtype=np.intc), np.array([a.idx_v for a, _ in ids], dtype=np.intc),
            np.array([b.idx_q for _, b in ids], dtype=np.intc), np.array([b.idx_v for _, b in ids], dtype=np.intc))


def set_targets(robot: Robot, packed: Packed, tasks: tuple[Task, ...]) -> None:
    """Copy each task's target (and the posture's reference) into the packed problem."""
    step = packed.step
    for k, i in enumerate(packed.targets):
        task = tasks[i]
        if isinstance(task, ComTask):
            step.set_point(k, task.target)
        else:
            step.set_pose(k, task.target.homogeneous)  # type: ignore[union-attr]
    if packed.posture >= 0:
        posture = tasks[packed.posture]
        assert isinstance(posture, PostureTask)
        packed.post_ref[:] = ev.checked_ref(robot, posture)
        if isinstance(posture.weight, np.ndarray):
            packed.post_w[:] = ev.posture_weight(robot, posture)


def target_of(task: Task) -> np.ndarray:
    """A task's target as the compiled step reads it: 12 numbers (R row-major, t), a CoM's in the last three."""
    if isinstance(task, ComTask):
        out = np.zeros(12)
        out[9:] = task.target
        return out
    return _pose(task.target)  # type: ignore[union-attr]
