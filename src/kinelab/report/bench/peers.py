"""Peer IK libraries for ``kinelab bench`` (the optional ``bench`` extra): each solves the same problems.

Every peer reads the same URDF, stripped to its kinematics (no meshes to resolve), with the same joint
limits; its answer is re-checked by :func:`kinelab.report.bench.protocol.check_solution` like kinelab's own.

- roboticstoolbox-python ``ik_LM`` (its C++ Levenberg–Marquardt, with its own restarts);
- TRAC-IK through ``pytracik`` (KDL Newton + SQP in parallel; limits set explicitly, ε = 5e-7);
- ikpy (scipy optimisation);
- pink (Pinocchio differential IK, a QP per step with the DAQP solver).
"""

from __future__ import annotations

import importlib.util
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from kinelab.analysis.oracles import tool_link as _tool_link
from kinelab.errors import KinelabError
from kinelab.ik.chain import PRISMATIC, chain_model
from kinelab.report.bench.protocol import TOL_POS, TOL_ROT, Case, Prepare, SolveFn
from kinelab.robot import Chain
from kinelab.scratch import scratch_dir

PEERS = {"rtb-ik_LM": "roboticstoolbox", "trac-ik": "pytracik", "ikpy": "ikpy", "pink": "pink"}


class PeerDeclinedError(KinelabError):
    """A peer does not take this robot or task (its model of the chain differs, say): a "Not run" line, said."""


class PeerFailedError(KinelabError):
    """An installed peer failed where it should run (its adapter or the peer broke): the bench stops, exit 1,
    rather than print figures without it."""

    exit_code = 1


def last_line(exc: BaseException) -> str:
    """An exception as its traceback's last line says it (one line, at most 300 characters)."""
    return " ".join(f"{type(exc).__name__}: {exc}".split())[:300]


def kinematic_urdf(robot: Chain) -> Path:
    """A copy of the robot's URDF without visual, collision, inertial, gazebo or transmission elements."""
    if robot.urdf_path is None:
        raise KinelabError(f"{robot.name} was made from an in-memory model: the peers read a URDF file")
    tree = ET.parse(robot.urdf_path)
    root = tree.getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision", "inertial"):
            for el in list(link.findall(tag)):
                link.remove(el)
    for tag in ("gazebo", "transmission"):
        for el in list(root.findall(tag)):
            root.remove(el)
    out = scratch_dir("kinelab-bench-") / f"{robot.name}.urdf"
    tree.write(out)
    return out


def tool_link(robot: Chain) -> str:
    """The URDF link the tool frame sits on (the peers take a link, not a frame)."""
    return _tool_link(robot)


def rtb_ets(robot: Chain) -> Any:
    """roboticstoolbox's ETS of the robot's base → tool chain (its URDF import), checked for the joint count.

    Raises:
        ImportError: roboticstoolbox is not installed; PeerDeclinedError: it sees another number of joints.
    """
    import roboticstoolbox as rtb

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ets = rtb.Robot.URDF(str(kinematic_urdf(robot))).ets(end=tool_link(robot))
    if ets.n != robot.n:
        raise PeerDeclinedError(f"roboticstoolbox sees {ets.n} joints, kinelab {robot.n}")
    return ets


def rtb_chain_ets(robot: Chain) -> Any:
    """roboticstoolbox's ETS built from kinelab's own joint data (placements, axes, limits), for chains
    whose URDF rtb imports wrongly (axes not along x, y or z): each joint is SE3(placement · A) · Rz(q)
    (or tz(q)) · SE3(Aᵀ), A a rotation taking z onto the joint axis. Checked against Pinocchio's FK.

    Raises:
        ImportError: roboticstoolbox is not installed; PeerDeclinedError: its FK disagrees with Pinocchio's.
    """
    from roboticstoolbox import ET, ETS

    ch = chain_model(robot).chain
    parts = []
    for i in range(robot.n):
        A = _z_onto(ch.axis_local[i])
        before, after = np.eye(4), np.eye(4)
        before[:3, :3], before[:3, 3], after[:3, :3] = ch.placement_R[i] @ A, ch.placement_t[i], A.T
        qlim = [robot.lower[i], robot.upper[i]]
        parts += [ET.SE3(before), ET.tz(qlim=qlim) if ch.kind[i] == PRISMATIC else ET.Rz(qlim=qlim), ET.SE3(after)]
    tool = np.eye(4)
    tool[:3, :3], tool[:3, 3] = ch.tool_R, ch.tool_t
    ets = ETS([*parts, ET.SE3(tool)])  # type: ignore[operator, unused-ignore]  # one list: * renumbered joints
    q = robot.random_q(0)
    if not np.allclose(np.asarray(ets.fkine(q).A), robot.fk(q).homogeneous, atol=1e-9):
        raise PeerDeclinedError("the ETS built from the chain disagrees with Pinocchio's FK")
    return ets


def _z_onto(axis: np.ndarray) -> np.ndarray:
    """A rotation matrix whose third column is the unit vector ``axis``."""
    z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


MASKS = {"pose": None, "position": np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
         "orientation": np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])}  # ik_LM's error weights; no "axis" mask exists
# the tasks each peer can be asked (the others are reported as not run)
TASKS = {"rtb-ik_LM": ("pose", "position", "orientation"), "trac-ik": ("pose",), "ikpy": ("pose",),
         "pink": ("pose",)}


def _rtb(robot: Chain, budget: float) -> SolveFn:
    ets = rtb_ets(robot)

    def run(case: Case, seed: int):
        # tol bounds E = ½ eᵀe (e in m and rad): 5e-13 keeps both parts below 1e-6
        sol = ets.ik_LM(case.oMtarget.homogeneous, q0=case.q_start, tol=5e-13, joint_limits=True,
                        mask=MASKS[case.task])
        return np.asarray(sol.q, dtype=float), int(sol.iterations)

    return run


def _tracik(robot: Chain, budget: float) -> SolveFn:
    from trac_ik.trac_ik import TracIK

    solver = TracIK(robot.base, tool_link(robot), str(kinematic_urdf(robot)), timeout=budget, epsilon=5e-7)
    if solver.dof != robot.n:
        raise PeerDeclinedError(f"TRAC-IK sees {solver.dof} joints, kinelab {robot.n}")
    solver.joint_limits = (list(robot.lower), list(robot.upper))

    def run(case: Case, seed: int):
        q = solver.ik(case.oMtarget.translation, case.oMtarget.rotation, case.q_start)
        return (None if q is None else np.asarray(q, dtype=float)), -1

    return run


def _ikpy(robot: Chain, budget: float) -> SolveFn:
    from ikpy.chain import Chain

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = Chain.from_urdf_file(str(kinematic_urdf(robot)), base_elements=[robot.base],
                                     last_link_vector=None)
    names = [link.name for link in chain.links]
    active = [names.index(j) for j in robot.joint_names if j in names]
    if len(active) != robot.n:
        raise PeerDeclinedError(f"ikpy's chain lacks some of {robot.joint_names}")
    mask = [i in active for i in range(len(names))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = Chain.from_urdf_file(str(kinematic_urdf(robot)), base_elements=[robot.base], active_links_mask=mask)

    def run(case: Case, seed: int):
        start = np.zeros(len(names))
        start[active] = case.q_start
        full = chain.inverse_kinematics_frame(case.oMtarget.homogeneous, initial_position=start,
                                              orientation_mode="all")
        return np.asarray(full)[active], -1

    return run


def _pink(robot: Chain, budget: float) -> SolveFn:
    import pink
    from pink.tasks import FrameTask

    task = FrameTask(robot.tool, position_cost=1.0, orientation_cost=1.0)
    if sum(f.name == robot.tool for f in robot.model.frames) > 1:  # pink finds a frame by its name alone
        raise PeerDeclinedError(f"pink names frames by name only, and {robot.tool!r} names "
                                f"{sum(f.name == robot.tool for f in robot.model.frames)} frames of this chain")

    def run(case: Case, seed: int):
        deadline = time.perf_counter() + budget
        conf = pink.Configuration(robot.model, robot.model.createData(), robot.to_pin_q(case.q_start))
        task.set_target(case.oMtarget)
        it = 0
        while time.perf_counter() < deadline:
            err = task.compute_error(conf)
            if np.linalg.norm(err[:3]) < TOL_POS and np.linalg.norm(err[3:]) < TOL_ROT:
                break
            velocity = pink.solve_ik(conf, [task], dt=1.0, solver="daqp", damping=1e-12)
            conf.integrate_inplace(velocity, 1.0)
            it += 1
        return robot.from_pin_q(conf.q), it

    return run


ADAPTERS: dict[str, Prepare] = {"rtb-ik_LM": _rtb, "trac-ik": _tracik, "ikpy": _ikpy, "pink": _pink}


def available() -> tuple[dict[str, Prepare], dict[str, str]]:
    """The installed peers, and for the others the install hint."""
    found, missing = {}, {}
    for name, module in PEERS.items():
        if importlib.util.find_spec(module) is None:
            missing[name] = "not installed: pip install -e '.[bench]'"
        else:
            found[name] = ADAPTERS[name]
    return found, missing
