"""#59: the differential step holds its limits exactly at every step — positions (1e-9) and velocities (1e-9
relative) — from starts inside and outside the limits, with targets it cannot reach; each limit test is run again
with that bound dropped, and must then see the violation (so that it can fail)."""

import numpy as np
import pinocchio as pin
import pytest

import kinelab
from kinelab.wholebody import ComTask, CouplingTask, FrameTask, Limits, PostureTask, StepOptions, step

FRAMES = {"talos": ("left_sole_link", "right_sole_link", "gripper_left_base_link", "gripper_right_base_link"),
          "g1": ("left_ankle_roll_link", "right_ankle_roll_link", "left_wrist_yaw_link", "right_wrist_yaw_link"),
          "baxter": ("left_gripper", "right_gripper"), "panda": ("panda_hand_tcp",)}


def robot_of(name):
    loaded = kinelab.load(name)
    return loaded.robot if isinstance(loaded, kinelab.Chain) else loaded


def far_tasks(robot, rng):
    """Each frame sent 1 m and a turn away (most unreachable), the CoM pulled, a random posture."""
    q = robot.random_q(rng)
    tasks = [FrameTask(f, T * pin.exp6(rng.normal(size=6))) for f, T in
             zip(FRAMES[robot.name], robot.frame_placements(q, FRAMES[robot.name]), strict=True)]
    return tasks + [ComTask(robot.com(q) + rng.normal(size=3)), PostureTask(robot.random_q(rng), weight=1e-2)]


def violations(robot, limits, steps=300, outside=False, seed=0):
    """(position, velocity) violations over ``steps`` steps of dt 0.01-0.2 s on far targets, the largest of each
    (positions [rad or m] past a limit; velocities as a share of their limit)."""
    rng = np.random.default_rng(seed)
    vmax = robot.velocity_limit
    q, worst_p, worst_v = robot.random_q(rng), 0.0, 0.0
    if outside:  # every bounded joint pushed past a limit by up to 0.3
        b = robot.space.bounded_q
        q[b] = np.where(rng.random(b.sum()) < 0.5, robot.lower[b] - 0.3 * rng.random(b.sum()),
                        robot.upper[b] + 0.3 * rng.random(b.sum()))
    tasks = far_tasks(robot, rng)
    for k in range(steps):
        if k % 50 == 0:
            tasks = far_tasks(robot, rng)
        dt = float(rng.uniform(0.01, 0.2))
        before = q.copy()
        result = step(robot, q, tasks, dt, limits=limits)
        assert result.solved, result.status
        q = result.q
        inside_before = (before >= robot.lower - 1e-9) & (before <= robot.upper + 1e-9)
        past = np.maximum(robot.lower - q, q - robot.upper)
        worst_p = max(worst_p, float(np.max(past[inside_before], initial=0.0)))
        finite = np.isfinite(vmax)
        worst_v = max(worst_v, float(np.max(np.abs(result.v[finite]) / vmax[finite] - 1.0, initial=0.0)))
    return worst_p, worst_v


@pytest.mark.parametrize("name", list(FRAMES))
def test_position_and_velocity_limits_hold_at_every_step(name):
    robot = robot_of(name)
    p, v = violations(robot, Limits())
    assert p <= 1e-9 and v <= 1e-9
    dropped_p, _ = violations(robot, Limits(position=False))
    _, dropped_v = violations(robot, Limits(velocity=None))
    assert dropped_p > 1e-3 and dropped_v > 1e-3  # the scenario does push on both bounds


@pytest.mark.parametrize("name", ["talos", "panda"])
def test_a_start_outside_its_limits_comes_back_at_the_velocity_limit(name):
    robot = robot_of(name)
    rng = np.random.default_rng(3)
    q = robot.random_q(rng)
    b = np.flatnonzero(robot.space.bounded_q)
    k = b[len(b) // 2]
    iv = robot.model.joints[[j for j in range(1, robot.model.njoints)
                             if robot.model.joints[j].idx_q == k][0]].idx_v
    q[k] = robot.upper[k] + 0.5
    vmax = robot.velocity_limit[iv]
    tasks = [PostureTask(q.copy(), weight=1.0)]  # a posture that asks to stay outside
    for _ in range(3):
        result = step(robot, q, tasks, 0.01)
        assert result.solved and robot.space.names_v[iv] in result.returning
        assert result.v[iv] == pytest.approx(-vmax, rel=1e-12)  # back at the limit's speed, not infeasible
        q = result.q
    limits = Limits(velocity=None)
    result = step(robot, q, tasks, 0.01, limits=limits)
    assert result.q[k] <= robot.upper[k] + 1e-9  # no velocity limit: back inside in one step


def test_acceleration_limits_hold_when_the_velocity_before_is_given():
    robot = robot_of("panda")
    rng = np.random.default_rng(5)
    q, v = robot.random_q(rng), np.zeros(robot.nv)
    tasks = far_tasks(robot, rng)
    for _ in range(100):
        result = step(robot, q, tasks, 0.01, limits=Limits(acceleration=2.0), v_prev=v)
        assert np.abs(result.v - v).max() <= 2.0 * 0.01 * (1 + 1e-9) + 1e-12
        q, v = result.q, result.v


def test_a_coupling_is_held_exactly():
    robot = robot_of("talos")
    rng = np.random.default_rng(9)
    q = robot.random_q(rng)
    tasks = [*far_tasks(robot, rng), CouplingTask("arm_left_1_joint", "arm_right_1_joint", ratio=-1.0, offset=0.0)]
    jl, jr = (robot.model.joints[robot.model.getJointId(n)].idx_q for n in ("arm_left_1_joint", "arm_right_1_joint"))
    for _ in range(20):
        q = step(robot, q, tasks, 0.05, limits=Limits(velocity=None)).q
    assert abs(q[jl] + q[jr]) <= 1e-9


def test_a_second_priority_acts_in_the_first_s_null_space():
    robot = robot_of("talos")
    rng = np.random.default_rng(11)
    q = robot.random_q(rng)
    frames = FRAMES["talos"]
    first = [FrameTask(f, T * pin.exp6(rng.normal(size=6) * 0.05)) for f, T in
             zip(frames, robot.frame_placements(q, frames), strict=True)]
    alone = step(robot, q, first, 0.05, limits=Limits(position=False, velocity=None))
    both = step(robot, q, [*first, PostureTask(robot.random_q(rng), weight=1.0, priority=2)], 0.05,
                limits=Limits(position=False, velocity=None))
    from kinelab.wholebody import evaluate as ev

    ev.forward(robot, q, com=False)
    A1 = np.vstack([ev.task_rows(robot, t)[0] for t in first])
    assert np.abs(A1 @ both.v - A1 @ alone.v).max() <= 1e-6 * np.abs(A1 @ alone.v).max()
    assert np.abs(both.v - alone.v).max() > 1e-3  # the posture did move the rest


def test_both_qp_solvers_give_the_same_step():
    robot = robot_of("g1")
    rng = np.random.default_rng(2)
    q = robot.random_q(rng)
    tasks = far_tasks(robot, rng)
    a = step(robot, q, tasks, 0.05, options=StepOptions(solver="daqp"))
    b = step(robot, q, tasks, 0.05, options=StepOptions(solver="proxsuite"))
    assert a.solved and b.solved and np.abs(a.v - b.v).max() <= 1e-5


@pytest.mark.parametrize("call, error, needle", [
    (lambda r: step("panda", np.zeros(7), [], 0.1), kinelab.ChainError, "whole robot .* or a chain"),
    (lambda r: step(r, r.neutral(), [], 0.1), kinelab.OptionError, "at least one"),
    (lambda r: step(r, r.neutral(), [FrameTask("nosuch", pin.SE3.Identity())], 0.1), kinelab.FrameNotFoundError,
     "nosuch"),
    (lambda r: step(r, r.neutral(), [PostureTask()], 0.0), kinelab.OptionError, "dt"),
    (lambda r: step(r, r.neutral(), [PostureTask()], 0.1, limits="x"), kinelab.OptionError, "Limits"),
    (lambda r: FrameTask("a", np.eye(3)), kinelab.TargetError, "4 × 4"),
    (lambda r: FrameTask("a", pin.SE3.Identity(), task="twist"), kinelab.OptionError, "pose"),
    (lambda r: ComTask([0, 0, 0], axes="xq"), kinelab.OptionError, "xyz"),
    (lambda r: Limits(velocity=-1.0), kinelab.OptionError, "velocity"),
    (lambda r: step(r, np.zeros(r.nq), [PostureTask()], 0.1), kinelab.ConfigurationError, "unit norm"),
])
def test_bad_input_to_the_step_is_named(call, error, needle):
    with pytest.raises(error, match=needle):
        call(robot_of("talos"))


@pytest.mark.parametrize("name", list(FRAMES))
def test_the_compiled_step_gives_the_readable_steps_answer(name):
    """The compiled path (kinelab.core._body) against the step written with Pinocchio's calls: every task's rate
    A·v within 1e-6 of the largest (v itself differs where only the damping decides it), the same errors, the same
    q where v agrees."""
    import importlib

    from kinelab.wholebody import RelativeFrameTask, compiled
    from kinelab.wholebody import evaluate as ev

    readable = importlib.import_module("kinelab.wholebody.step")._step
    robot = robot_of(name)
    assert robot.derived("compiled tree", compiled.pack_tree) is not None  # certified against Pinocchio
    rng = np.random.default_rng(17)
    frames = FRAMES[name]
    for k in range(12):
        q, qt = robot.random_q(rng), robot.random_q(rng)
        placed = robot.frame_placements(qt, frames)
        tasks = [FrameTask(f, T, task=("pose", "position", "orientation", "axis")[k % 4])
                 for f, T in zip(frames, placed, strict=True)]
        if len(frames) > 1:
            tasks.append(RelativeFrameTask(frames[0], frames[1], placed[1].inverse() * placed[0]))
        weight = 1e-2 if k % 3 else rng.uniform(0.0, 1e-2, robot.nv)  # one weight, or one per velocity
        tasks += [ComTask(robot.com(qt), axes="xy"), PostureTask(robot.random_q(rng), weight=weight,
                                                                 priority=1 + k % 2)]
        fast = step(robot, q, tasks, 0.05)
        slow = readable(robot, q, tuple(tasks), 0.05, Limits(), StepOptions(), None)
        assert fast.solved and slow.solved
        ev.forward(robot, q, com=True)
        for task in tasks[:-1]:
            A = ev.task_rows(robot, task)[0]
            assert np.abs(A @ (fast.v - slow.v)).max() <= 1e-6 * max(1.0, np.abs(A @ slow.v).max()), task.label
        for a, b in zip(fast.errors, slow.errors, strict=True):
            assert a.label == b.label and abs(a.position - b.position) <= 1e-12 and abs(a.rotation - b.rotation) <= 1e-9


def test_a_posture_weighs_each_velocity_as_asked():
    """Per-velocity weights: a joint weighted zero is not pulled, the others are, exactly as a QP with that diagonal
    says: with nothing else asked, v = gain·(q_ref ⊖ q)/dt on the weighted joints and 0 on the others."""
    panda = kinelab.load("panda").robot
    q, q_ref = panda.random_q(1), panda.random_q(2)
    weight = np.ones(panda.nv)
    weight[[1, 4]] = 0.0
    res = step(panda, q, PostureTask(q_ref, weight=weight), 1.0, limits=Limits(position=False, velocity=None),
               options=StepOptions(damping=1e-12))
    want = np.asarray(pin.difference(panda.model, q, q_ref))
    want[[1, 4]] = 0.0
    assert np.abs(res.v - want).max() <= 1e-6
    with pytest.raises(kinelab.KinelabError, match="nv = "):
        step(panda, q, PostureTask(q_ref, weight=np.ones(3)), 1.0)
    with pytest.raises(kinelab.KinelabError, match="one per velocity"):
        PostureTask(q_ref, weight=[1.0, -1.0])


@pytest.mark.parametrize("dropped", ["position", "velocity"])
def test_the_limit_check_fails_when_a_bound_is_dropped(monkeypatch, dropped):
    """The check `kinelab validate` runs (2000 steps, starts outside the limits) must see a step that leaves out a
    bound: the readable step with its position (or velocity) bounds dropped makes it count violations."""
    import importlib

    from kinelab.report.wholebody_checks import limits_check

    limits_module = importlib.import_module("kinelab.wholebody.limits")  # JointLimits.bounds calls its bounds()
    baxter = kinelab.load("baxter")
    assert limits_check(baxter, 10, 0)[0].value == 0  # as built: none
    original = limits_module.bounds

    def without(space, q, dt, vmax, position, amax, v_prev):
        if dropped == "velocity":
            vmax = np.full_like(vmax, np.inf)
        return original(space, q, dt, vmax, position and dropped != "position", amax, v_prev)

    problem_module = importlib.import_module("kinelab.wholebody.problem")
    monkeypatch.setattr(problem_module.WholeBody, "_compiled_step", lambda *args: None)  # the readable step, whose
    # bounds are patched
    monkeypatch.setattr(limits_module, "bounds", without)
    assert limits_check(baxter, 10, 0)[0].value > 0


@pytest.mark.parametrize("name", ["panda", "talos"])
def test_a_damping_task_is_the_same_step_compiled_and_readable(name):
    """#68: DampingTask (pink's and mink's) is one class, in both steps: each task's rate and error agree between
    the compiled and the readable step, at priority 1 and 2, one weight or one per velocity."""
    import importlib

    from kinelab import DampingTask
    from kinelab.wholebody import evaluate as ev

    readable = importlib.import_module("kinelab.wholebody.step")._step
    robot = robot_of(name)
    rng = np.random.default_rng(23)
    frames = FRAMES[name]
    for k in range(8):
        q, qt = robot.random_q(rng), robot.random_q(rng)
        tasks = [FrameTask(f, T, task="position") for f, T in zip(frames, robot.frame_placements(qt, frames),
                                                                     strict=True)]
        weight = 0.5 if k % 2 else rng.uniform(0.0, 1.0, robot.nv)
        tasks += [DampingTask(weight, priority=1 + (k // 2) % 2), ComTask(robot.com(qt), axes="xy", priority=2)]
        fast = step(robot, q, tasks, 0.05)
        slow = readable(robot, q, tuple(tasks), 0.05, Limits(), StepOptions(), None)
        assert fast.solved and slow.solved
        assert np.abs(fast.v - slow.v).max() <= 1e-6 * max(1.0, np.abs(slow.v).max())
        ev.forward(robot, q, com=True)
        for a, b in zip(fast.errors, slow.errors, strict=True):
            assert a.label == b.label and abs(a.position - b.position) <= 1e-12 and abs(a.rotation - b.rotation) <= 1e-9


def test_a_damping_task_is_ridge_regression_by_numpy():
    """Unbounded, one position task and DampingTask(w): v = (AᵀA + (w + λ) I)⁻¹ Aᵀ b, b = −e/dt, by NumPy."""
    from kinelab import DampingTask

    robot = robot_of("panda")
    rng = np.random.default_rng(4)
    q = robot.random_q(rng)
    frame = FRAMES["panda"][0]
    target = robot.frame_placement(q, frame).translation + np.array([0.05, -0.02, 0.03])
    dt, w, lam = 0.1, 0.3, 1e-6
    res = step(robot, q, [FrameTask(frame, target, task="position"), DampingTask(w)], dt,
               limits=Limits(position=False, velocity=None))
    pin.computeJointJacobians(robot.model, robot.data, q)
    pin.updateFramePlacements(robot.model, robot.data)
    fid = robot.model.getFrameId(frame)
    A = pin.getFrameJacobian(robot.model, robot.data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:3]
    b = -(robot.data.oMf[fid].translation - target) / dt
    expected = np.linalg.solve(A.T @ A + (w + lam) * np.eye(robot.nv), A.T @ b)
    assert res.solved and np.abs(res.v - expected).max() <= 1e-8 * max(1.0, np.abs(expected).max())
    plain = step(robot, q, [FrameTask(frame, target, task="position")], dt, limits=Limits(position=False,
                                                                                         velocity=None))
    assert np.linalg.norm(res.v) < np.linalg.norm(plain.v)  # the damping slows what the task leaves free
