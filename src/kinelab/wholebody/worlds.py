"""Many worlds a step: :meth:`kinelab.WholeBody.step_batch` — N configurations of one robot, each with its own
targets, stepped in one call (reinforcement learning's thousands of simulated robots, data generation).

The worlds share the problem (tasks, weights, limits, posture reference); each has its configuration, its task
targets and its warm start (the bounds active at its last answer, kept between calls for the same N). The compiled
step runs them with the GIL released, one copy of the step per thread (its own tree and buffers), the worlds split
into one contiguous chunk per thread: on a 2-core machine, two worlds at once. World w's answer is the one
:meth:`~kinelab.WholeBody.step` gives from ``Q[w]`` with those targets (the same code; the warm start changes
DAQP's path, not its answer). A problem the compiled step does not take steps each world by the readable step.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import ArrayLike

from kinelab.errors import OptionError
from kinelab.wholebody import compiled as cp
from kinelab.wholebody.step import _step
from kinelab.wholebody.targets import TargetError

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from kinelab.robot.tree import Robot
    from kinelab.wholebody.limits import Limits
    from kinelab.wholebody.step import StepOptions
    from kinelab.wholebody.tasks import Task

    Targets = Mapping[Any, ArrayLike] | Sequence[tuple[Any, ArrayLike]]


class WholeBody(Protocol):
    """What the worlds read of their problem (:class:`kinelab.WholeBody`, which imports this module)."""

    robot: Robot
    limits: Limits
    options: StepOptions
    loops: tuple[Task, ...]
    _packed: cp.Packed | None
    _vmax: np.ndarray
    _amax: np.ndarray

    @property
    def tasks(self) -> tuple[Task, ...]:
        """The tasks as they are now."""

    def _index(self, task: Any) -> int: ...


@dataclass(frozen=True)
class BatchStep:
    """N worlds' step.

    Attributes:
        q: (N, nq) each world's configuration after dt; v: (N, nv) its velocity [rad/s or m/s];
        solved: (N,) whether world w's QP solved (else its v is zero and its q unmoved); flags: (N,) the compiled
        step's outcome codes (:class:`kinelab.wholebody.compiled.Outcome`); iterations: (N,) DAQP's.
    """

    q: np.ndarray
    v: np.ndarray
    solved: np.ndarray
    flags: np.ndarray
    iterations: np.ndarray

    @property
    def status(self) -> list[str]:
        """Each world's status in words (the readable step's)."""
        return [cp.Outcome(int(f)).words for f in self.flags]


class Worlds:
    """A problem's per-thread copies of its compiled step and its worlds' warm starts (the threads themselves are
    the process's, shared by every problem)."""

    def __init__(self, problem: WholeBody, threads: int | None = None):
        self.problem = problem
        self.threads = max(1, min(threads or os.cpu_count() or 1, 64))
        packed = problem._packed
        trees = [cp.build_tree(problem.robot) for _ in range(self.threads)] if packed is not None else []
        self.steps = [cp._body.Step(tree, packed.problem) for tree in trees if tree is not None] if packed else []
        self.pool = _pool(self.threads) if len(self.steps) > 1 else None
        self.warm = np.zeros((0, problem.robot.nv), dtype=np.intc)
        self.labels = packed.labels if packed is not None else ()  # what the compiled step packed, if it did
        self.slots = packed.slots if packed is not None else ()
        self.weighted = len(packed.problem.kind) if packed is not None else 0

    def step(self, Q: ArrayLike, dt: float, targets: Targets | None, v_prev: ArrayLike | None) -> BatchStep:
        """Every world one step (see the module's docstring); ``targets``: per task (the task or its index) an
        (N, 4, 4) array of poses or an (N, 3) array of points [m], as a mapping or (task, array) pairs; the others
        keep the task's own target.

        Raises:
            OptionError, TargetError: a bad array or task (named).
        """
        problem, robot = self.problem, self.problem.robot
        Q = _worlds(Q, robot.nq, "Q")
        n = Q.shape[0]
        for q in Q if problem.loops else ():  # onto what the robot itself holds, as the single step starts
            for task in problem.loops:
                task.project(robot, q)
        prev = np.zeros((0, robot.nv)) if v_prev is None else _worlds(v_prev, robot.nv, "v_prev", n)
        if problem._amax.size and v_prev is None:
            raise OptionError("v_prev", None, "each world's velocity before the step (N × nv): the limits hold "
                                              "accelerations")
        given = _pairs(targets)
        if not self.steps or not problem.limits.compiled:
            return _readable(problem, Q, dt, given, prev)
        T = self._targets(n, given)
        if self.warm.shape[0] != n:
            self.warm = np.zeros((n, robot.nv), dtype=np.intc)
        out = BatchStep(np.empty((n, robot.nq)), np.empty((n, robot.nv)), np.zeros(n, dtype=bool),
                        np.empty(n, dtype=np.intc), np.empty(n, dtype=np.intc))
        chunks = np.array_split(np.arange(n), len(self.steps))
        jobs = [(step, chunk[0], chunk[-1] + 1) for step, chunk in zip(self.steps, chunks, strict=True) if chunk.size]
        run = lambda job: self._chunk(job, Q, dt, T, prev, out)  # noqa: E731
        list(self.pool.map(run, jobs) if self.pool is not None and len(jobs) > 1 else map(run, jobs))
        out.solved[:] = np.isin(out.flags, (cp.Outcome.SOLVED, cp.Outcome.SOLVED_SOFT))
        return out

    def _chunk(self, job: tuple[Any, int, int], Q: np.ndarray, dt: float, T: np.ndarray, prev: np.ndarray,
               out: BatchStep) -> None:
        """Worlds a..b on one thread's step (the GIL released inside)."""
        step, a, b = job
        problem, nv = self.problem, self.problem.robot.nv
        errors = np.zeros((max(len(self.labels), 1), 2))
        step.step_many(Q[a:b], dt, T[a:b], problem._vmax, problem.limits.position, problem._amax,
                       prev[a:b] if prev.shape[0] else prev, problem.options.damping, out.q[a:b], out.v[a:b],
                       out.flags[a:b], out.iterations[a:b], self.warm[a:b], errors, np.zeros(nv, dtype=np.uint8))

    def _targets(self, n: int, given: list[tuple[Any, ArrayLike]]) -> np.ndarray:
        """(N, weighted tasks, 12): every task's own target in every world, the given ones per world."""
        problem, slots = self.problem, self.slots
        row = _Rows(self.weighted)
        for task, slot in zip(problem.tasks, slots[:len(problem.tasks)], strict=True):  # then the robot's own loops
            if slot >= 0:
                task.refresh(row, problem.robot, slot)
        T = np.repeat(row.rows[None], n, axis=0)
        for key, value in given:
            i = problem._index(key)
            slot = slots[i]
            if slot < 0:
                raise OptionError("targets", key, "a task with a target (a frame, a relative frame or the centre of "
                                                  "mass)")
            _place(T, slot, value, n, problem.tasks[i].label)
        return T


_POOLS: dict[int, ThreadPoolExecutor] = {}


def _pool(threads: int) -> ThreadPoolExecutor:
    """The process's pool of ``threads`` threads, shared by every problem's worlds (made at its first use)."""
    if threads not in _POOLS:
        _POOLS[threads] = ThreadPoolExecutor(threads, thread_name_prefix="kinelab-worlds")
    return _POOLS[threads]


class _Rows:
    """What a task's :meth:`~kinelab.wholebody.tasks.Task.refresh` writes, as rows of 12 (R row-major, t)."""

    def __init__(self, slots: int):
        self.rows = np.zeros((slots, 12))

    def set_pose(self, slot: int, H: np.ndarray) -> None:
        self.rows[slot, :9], self.rows[slot, 9:] = H[:3, :3].ravel(), H[:3, 3]

    def set_point(self, slot: int, p: np.ndarray) -> None:
        self.rows[slot, 9:] = p

    def set_posture(self, q_ref: np.ndarray, weights: np.ndarray | None) -> None:
        return None  # the posture's reference is the problem's, shared by every world


def _pairs(targets: Targets | None) -> list[tuple[Any, ArrayLike]]:
    """The per-world targets as (task or index, array) pairs.

    Raises:
        OptionError: neither a mapping nor pairs.
    """
    if targets is None:
        return []
    items = targets.items() if hasattr(targets, "items") else targets
    try:
        pairs = [(key, value) for key, value in items]
    except (TypeError, ValueError):
        raise OptionError("targets", targets, "a mapping {task or index: array}, or (task, array) pairs") from None
    return pairs


def _place(T: np.ndarray, slot: int, value: ArrayLike, n: int, label: str) -> None:
    """Per-world targets of one task into T: (N, 4, 4) poses (proper rotations, finite) or (N, 3) points."""
    arr = np.asarray(value, dtype=float)
    if arr.shape == (n, 3) and np.isfinite(arr).all():
        T[:, slot, 9:] = arr
        return
    if arr.shape != (n, 4, 4) or not np.isfinite(arr).all():
        raise TargetError(f"the targets of {label} must be an (N, 4, 4) array of poses or an (N, 3) array of points "
                          f"with N = {n} worlds, finite; got shape {arr.shape}")
    R = arr[:, :3, :3]
    gap = np.abs(np.einsum("nji,njk->nik", R, R) - np.eye(3)).max(axis=(1, 2))
    bad = np.flatnonzero((gap > 1e-6) | (np.linalg.det(R) <= 0) | (np.abs(arr[:, 3] - [0, 0, 0, 1]).max(axis=1) > 0))
    if bad.size:
        raise TargetError(f"the target of {label} in world {bad[0]} is not a pose with a proper rotation "
                          "(orthonormal within 1e-6, det +1, last row 0, 0, 0, 1)")
    T[:, slot, :9], T[:, slot, 9:] = R.reshape(n, 9), arr[:, :3, 3]


def _worlds(value: ArrayLike, width: int, name: str, n: int | None = None) -> np.ndarray:
    """(N, width) finite floats, C-contiguous, a copy (N = n when given).

    Raises:
        OptionError: another shape, NaN/inf or not numbers.
    """
    try:
        arr = np.array(value, dtype=float, order="C")  # a copy: the caller's rows are not moved onto the loops
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.ndim != 2 or arr.shape[1] != width or (n is not None and arr.shape[0] != n) or arr.shape[0] == 0 \
            or not np.isfinite(arr).all():
        rows = "N" if n is None else str(n)
        raise OptionError(name, f"an array of shape {getattr(arr, 'shape', '?')}",
                          f"{rows} × {width} finite numbers (one row per world)")
    return arr


def _readable(problem: WholeBody, Q: np.ndarray, dt: float, given: list[tuple[Any, ArrayLike]], prev: np.ndarray
              ) -> BatchStep:
    """Every world by the readable step, each given task moved to its world's target (a problem the compiled step
    does not take)."""
    n, robot = Q.shape[0], problem.robot
    moved = {problem._index(k): np.asarray(v, dtype=float) for k, v in given}
    for i, arr in moved.items():
        if arr.ndim < 2 or arr.shape[0] != n:
            raise TargetError(f"the targets of {problem.tasks[i].label} must be one per world (N = {n}), got an "
                              f"array of shape {arr.shape}")
    out = BatchStep(np.empty((n, robot.nq)), np.empty((n, robot.nv)), np.zeros(n, dtype=bool),
                    np.zeros(n, dtype=np.intc), np.zeros(n, dtype=np.intc))
    for w in range(n):
        tasks = [t.moved(moved[i][w]) if i in moved else t for i, t in enumerate(problem.tasks)]
        res = _step(robot, robot.check_q(Q[w]), (*tasks, *problem.loops), dt, problem.limits, problem.options,
                    prev[w] if prev.shape[0] else None)
        out.q[w], out.v[w], out.solved[w], out.iterations[w] = res.q, res.v, res.solved, res.iterations
        out.flags[w] = _CODES.get(res.status, cp.Outcome.INFEASIBLE)
    return out


_CODES = {outcome.words: int(outcome) for outcome in reversed(cp.Outcome)}  # "solved": 1
