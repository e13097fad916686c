"""IKResult and Status: what every kinelab IK solver returns."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from enum import Enum
from typing import Any, TypeVar, overload

import numpy as np


class _Word(str, Enum):
    """A word of kinelab's vocabulary: compares equal to its string, hashes as it (a dict keyed by the word finds
    the member) and prints as it."""

    def __hash__(self) -> int:
        return str.__hash__(self)

    def __str__(self) -> str:
        return str(self.value)

    def __format__(self, spec: str) -> str:
        return format(str(self.value), spec)


class Status(_Word):
    """Why a solve ended. Only ``converged`` goes with success, and only after Pinocchio's check."""

    CONVERGED = "converged"
    UNREACHABLE = "unreachable"  # the target is out of the workspace (proved, or every start agreed)
    SINGULAR = "singular"  # stopped at a kinematic singularity with the target not reached
    STALLED = "stalled"  # stopped at a stationary point (local minimum, joint limit) short of the target
    MAX_ITERATIONS = "max_iterations"
    TIME_BUDGET = "time_budget"
    OUTSIDE_LIMITS = "outside_limits"  # the pose is met, but only with a joint outside its limits
    COLLISION = "collision"  # the pose is met, but every answer found collides (``collisions=``)
    NOT_FOUND = "not_found"  # a search found no answer, and none is proved not to exist
    JUMP = "jump"  # a tracked sample met its pose, but by a joint step larger than the path's jump limit

    @property
    def code(self) -> int:
        """The status's integer code: its place in the class (how arrays of results store it)."""
        return _CODES[self]

    @staticmethod
    def of_codes(codes: np.ndarray) -> np.ndarray:
        """The statuses of an array of codes, as an object array of :class:`Status` members (same shape)."""
        return _MEMBERS[np.asarray(codes, dtype=np.intp)]

    @staticmethod
    def codes(statuses: Iterable[Any]) -> np.ndarray:
        """The int8 codes of statuses given as members or their string values.

        Raises:
            ValueError: a value that names no status.
        """
        return np.array([Status(s).code for s in statuses], dtype=np.int8)


_MEMBERS = np.array(list(Status), dtype=object)
_CODES = {s: k for k, s in enumerate(Status)}


class Method(_Word):
    """How a set of branches was found (:attr:`Branches.method`)."""

    CLOSED_FORM = "closed form"  # every branch, from the chain's closed form
    SEARCH = "search"  # the 1-D search: every branch, measured complete
    ELIMINATION = "elimination"  # the general 6R elimination
    MULTISTART = "multistart"  # those seeded starts found
    SWEEP = "sweep"  # a redundant arm's joint swept: every branch at each sampled value
    UNKNOWN = ""


class Completeness(_Word):
    """How complete a set of branches is known to be (:attr:`Branches.complete`)."""

    CERTIFIED = "certified"  # every branch proved a root and the set proved to be every root within the limits
    SEARCH = "search"  # every branch a search or a closed form found, not proved complete
    ESTIMATE = "estimate"  # the multistart: ``unseen`` estimates what it missed
    UNKNOWN = ""


@dataclass(frozen=True)
class SingularEvent:
    """One firing of a monitor (FRDM's Σ|Δq| or window test, the compiled multistart's stalls, or the
    tracking jump monitor), with its diagnosis.

    Attributes:
        trigger: "step" (Σ|Δq| below eps_q), "window" (the objective stopped falling), "stall" (the
            compiled multistart, which restarts instead of diagnosing) or "jump" (tracking).
        diagnosis: "singular" (σ_min of the scaled Jacobian below 1e-4), "stationary", or a note.
        sweep: the sweep at which it fired; sample: the path sample (tracking); count: how many stalls.
        sigma_min: σ_min of the scaled Jacobian; position_error [m], rotation_error [rad] at that point.
        q: the configuration [rad or m]; max_joint_step: the jump [rad or m] (tracking).
    """

    trigger: str
    diagnosis: str | None = None
    sweep: int | None = None
    sample: int | None = None
    count: int | None = None
    sigma_min: float | None = None
    position_error: float | None = None
    rotation_error: float | None = None
    q: tuple[float, ...] | None = None
    max_joint_step: float | None = None

    def at_sample(self, k: int) -> SingularEvent:
        """The same event, located at path sample k."""
        return replace(self, sample=k)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: the fields that are set."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items() if v is not None}


@dataclass(frozen=True)
class BypassRecord:
    """One bypass switched on: ``bypass`` is "kicks", "intervals", "freeze" or "auto_kick".

    Attributes:
        sweep: the sweep at which it was applied (a solve); sample: the path sample (tracking).
        q: the configuration after it was applied [rad or m]; hold: samples it stays on, or "path".
    """

    bypass: str
    sweep: int | None = None
    sample: int | None = None
    q: tuple[float, ...] | None = None
    hold: int | str | None = None

    def at_sample(self, k: int) -> BypassRecord:
        """The same record, located at path sample k."""
        return replace(self, sample=k)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: the fields that are set."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items() if v is not None}


@dataclass(frozen=True)
class BiquatTrajectory:
    """The biquaternion solver's recorded run (``BiquatOptions(record=True)``), one row per step.

    Attributes:
        t: (K,) model time [s]; q: (K, nq) Pinocchio configurations; M: (K, 8) the error biquaternion M*
            (real w, x, y, z, then dual w, x, y, z); U: (K, 6) the control [v; ω].
    """

    t: np.ndarray
    q: np.ndarray
    M: np.ndarray
    U: np.ndarray


_D = TypeVar("_D", bound="Diagnostics")


@dataclass(frozen=True, repr=False)
class Diagnostics:
    """How a solve ran: the fields every solver's result has, each None (or "", or empty) where it does not apply.
    A solver with more to say has its own record (:class:`FRDMDiagnostics`, :class:`BiquatDiagnostics`); DLS,
    the closed form and the branch searches use this one.

    The fields come in groups: the run's (path to outside_limits, polished), the answer's own attempt
    (answer_events, answer_bypasses), the search for branches (branches to unseen) and collisions (contact,
    clear_after).
    """

    path: str = ""
    """"compiled" (a compiled kernel ran the attempts) or "" (the Python loop)."""
    attempts: int | None = None
    """Attempts run: the first start and its restarts."""
    stalls: int | None = None
    """Attempts that stalled."""
    message: str = ""
    """A solver's own note (a biquaternion run stopped by a singular matrix, say)."""
    outside_limits: int | None = None
    """Compiled attempts restarted because their answer left the limits."""
    polished: int | None = None
    """Attempts finished by Gauss–Newton steps after a stall (FRDM), or 1 when a closed-form answer was finished
    by a warm-started FRDM solve."""
    answer_events: tuple[SingularEvent, ...] = ()
    """The monitor events of the answer's own attempt (the result's ``singular_events`` cover every attempt)."""
    answer_bypasses: tuple[BypassRecord, ...] = ()
    """The bypasses of the answer's own attempt (the result's ``bypasses`` cover every attempt)."""
    branches: int | None = None
    """Distinct solutions: found by the search (``solve(prefer=)``), or that exist within the limits (closed
    form, ``solver == "analytic"``)."""
    found: int | None = None
    """Starts that reached this solution (multistart), or the roots merged into it (closed form: 2 at a double
    root)."""
    starts: int | None = None
    """Starts run (``solve_all``'s multistart)."""
    unseen: float | None = None
    """The estimated chance that one more start would find a new branch (multistart; 0 for the closed form)."""
    contact: Any = None
    """With ``collisions=``: the colliding pair of the answer (a :class:`kinelab.collision.Contact`: the two
    objects' names and their distance [m]), or None when it is clear."""
    clear_after: int | None = None
    """With ``collisions=``: the answers found that collided before this one (each a full solve from new
    starts)."""

    @classmethod
    def quick(cls: type[_D], **values: object) -> _D:
        """Diagnostics with these fields set (names and types the caller's own, unchecked): what a compiled
        solve builds on every call, without the frozen dataclass's per-field setattr (≈ 1 µs, not ≈ 9)."""
        made = object.__new__(cls)
        made.__dict__.update(values)  # the other fields read their defaults from the class
        return made

    def __repr__(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items()) + ")"

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: the fields that are set (events as dicts; the recorded trajectory left out)."""
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None or value == "" or f.name == "trajectory":
                continue
            if f.name in ("answer_events", "answer_bypasses"):
                value = [v.to_dict() for v in value]
            elif f.name == "contact":
                value = asdict(value)
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out


@dataclass(frozen=True, repr=False)
class FRDMDiagnostics(Diagnostics):
    """How an FRDM solve ran: :class:`Diagnostics`' fields and FRDM's own."""

    order: str = ""
    """The sweep order."""
    relax: float | None = None
    """The relaxation factor."""
    w_p: float | None = None
    """The position weight [1/m²]."""
    objective: float | None = None
    """The objective at the answer."""
    trace: tuple[float, ...] | None = None
    """The objective after every sweep (``trace=True``)."""
    sweeps: int | None = None
    """Sweeps of the answer's run."""
    accelerated_sweeps: int | None = None
    """Sweeps whose Anderson extrapolation was kept."""
    newton_steps: int | None = None
    """Gauss–Newton steps of the Newton finish, over every attempt."""
    polish_iterations: int | None = None
    """DLS steps after FRDM (``polish=True``)."""


@dataclass(frozen=True, repr=False)
class BiquatDiagnostics(Diagnostics):
    """How a biquaternion solve ran: :class:`Diagnostics`' fields and the integration's."""

    law: str = ""
    """The control law that ran."""
    model_time: float | None = None
    """The run's model time [s]."""
    steps: int | None = None
    """Integration steps."""
    integrator: str = ""
    """The integrator."""
    M0: float | None = None
    """The scalar of N̄∘Λ at the end of the run (±1 at the target)."""
    damping: float | None = None
    """The damping of the pseudo-inverse."""
    trajectory: BiquatTrajectory | None = None
    """The recorded run (``record=True``)."""


NO_DIAGNOSTICS = Diagnostics()


class _Deferred:
    """A result's ``diagnostics`` built only when read: a compiled solve (:mod:`kinelab.core._engine`) stores how to
    make it (``_make_diagnostics`` in the instance's dict, a callable) instead of the record; the first read makes
    it and keeps it. Results built the usual way store the record itself, which shadows this (a non-data
    descriptor)."""

    def __get__(self, obj: Any, owner: Any = None) -> Diagnostics:
        if obj is None:
            return NO_DIAGNOSTICS  # the field's default (the dataclass reads it here)
        make = obj.__dict__.pop("_make_diagnostics", None)
        made: Diagnostics = NO_DIAGNOSTICS if make is None else make()
        obj.__dict__["diagnostics"] = made
        return made


@dataclass(frozen=True)
class IKResult:
    """The outcome of :func:`kinelab.solve` (frozen: ``dataclasses.replace`` makes a changed copy; the compiled
    routes build it with :func:`kinelab.core._engine.fast_result`).

    ``position_error`` [m] and ``rotation_error`` [rad] are measured by the FK of the returned ``q`` that
    ``judge`` names — Pinocchio's, or kinelab's compiled chain FK where the robot's certificate found it equal to
    Pinocchio's (``robot.fk_certificate``) — against the target. ``success`` is true only when both are within
    tolerance and ``q`` is within the joint limits. ``q`` is one number per joint (rad, m) in the robot's joint order.
    """

    q: np.ndarray
    success: bool
    status: Status
    position_error: float
    rotation_error: float
    iterations: int
    restarts: int
    wall_time: float  # [s]
    solver: str
    mode: str = ""  # which variant produced the figures, e.g. "frdm (anderson)", "frdm+polish"
    singular_events: list[SingularEvent] = field(default_factory=list)
    bypasses: list[BypassRecord] = field(default_factory=list)
    message: str = ""
    diagnostics: Diagnostics = _Deferred()  # type: ignore[assignment]
    task: str = "pose"  # the components judged: pose, position, axis (with its axis) or orientation
    judge: str = "Pinocchio FK"  # whose FK measured the errors: "Pinocchio FK" or "compiled FK (certified)"

    def __getstate__(self) -> dict[str, Any]:
        """The fields, diagnostics built (a pickle or a copy never carries the maker)."""
        _ = self.diagnostics
        return self.__dict__

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (the CLI's ``ik --json``; fields are only ever added)."""
        return {
            "task": self.task,
            "judge": self.judge,
            "q": np.asarray(self.q).tolist(),
            "success": self.success,
            "status": self.status.value,
            "position_error_m": self.position_error,
            "rotation_error_rad": self.rotation_error,
            "iterations": self.iterations,
            "restarts": self.restarts,
            "wall_time_s": self.wall_time,
            "solver": self.solver,
            "mode": self.mode,
            "singular_events": [e.to_dict() for e in self.singular_events],
            "bypasses": [b.to_dict() for b in self.bypasses],
            "message": self.message,
            "info": self.diagnostics.to_dict(),
        }


class Branches(Sequence[IKResult]):
    """The distinct solutions of one target, as :func:`kinelab.solve_all` returns them: every branch as arrays, and
    a sequence of :class:`IKResult` (nearest ``q_ref`` first when asked) built only when indexed or iterated.

    Attributes:
        q: (k, n) the branches [rad or m], one row per branch (k = 0: (0, n)).
        position_error: (k,) [m] and rotation_error: (k,) [rad], by the FK each result's ``judge`` names.
        status: ``converged`` when it holds a branch that met the target; else why there is none:
            ``unreachable`` (proved: the target point lies beyond the reach bound, or the closed form or the search,
            which return every branch, have none within the joint limits), ``time_budget`` (the multistart's budget
            ran out before any start met the target: nothing was proved) or ``collision`` (every branch found
            collides).
        message: the reason in words ("" for a set of branches).
        method: how the set was found, and so how complete it is: "closed form" (every branch), "search" (the 1-D
            search: every branch, measured complete), "multistart" (those seeded starts found: ``unseen`` says
            how likely one more start would find another), "sweep" (a redundant arm's joint swept: every branch at
            each sampled value) or "" (unknown).
        unseen: the estimated chance that one more start would find a new branch (multistart), 0 for a closed form
            or a search, None when not known.
        complete: how complete the set is known to be (computed when first read): "certified" (each branch proved
            a root by Kantorovich's test, and the set proved to be every root within the limits: the general 6R
            elimination's eigenvalue count, or a closed form with no double root), "search" (every branch a
            search or a closed form found, not proved complete: ``complete_reason`` says why), "estimate" (the
            multistart: ``unseen`` estimates what it missed) or "" (unknown).
        complete_reason: why the set is not certified ("" when it is).
    """

    def __init__(self, found: Iterable[IKResult] = (), status: Status | None = None, message: str = "",
                 method: Method | str = "", unseen: float | None = None):
        results = list(found)
        self._results: list[IKResult] | None = results
        self._make_row: Callable[[Any, int], IKResult] = _called
        self._data: Any = None
        self.q = np.array([r.q for r in results], dtype=float) if results else np.empty((0, 0))
        self.position_error = np.array([r.position_error for r in results], dtype=float)
        self.rotation_error = np.array([r.rotation_error for r in results], dtype=float)
        self.status = status if status is not None else Status.CONVERGED if results else Status.TIME_BUDGET
        self.message, self.method, self.unseen = message, Method(method), unseen
        self._certify: Any = None

    @classmethod
    def from_arrays(cls, q: np.ndarray, position_error: np.ndarray, rotation_error: np.ndarray,
                    make: Callable[[int], IKResult], status: Status | None = None, message: str = "",
                    method: Method | str = "", unseen: float | None = None) -> Branches:
        """The branches as arrays (q: (k, n), the errors: (k,)); ``make(i)`` builds the i-th result when the set is
        first indexed or iterated."""
        made = cls.__new__(cls)
        made.q, made.position_error, made.rotation_error = q, position_error, rotation_error
        made._results, made._make_row, made._data = None, _called, make
        made.status = status if status is not None else Status.CONVERGED if len(q) else Status.TIME_BUDGET
        made.message, made.method, made.unseen = message, Method(method), unseen
        made._certify = None
        return made

    @classmethod
    def of_rows(cls, q: np.ndarray, position_error: np.ndarray, rotation_error: np.ndarray,
                make_row: Callable[[Any, int], IKResult], data: Any, method: Method,
                unseen: float | None) -> Branches:
        """A set of at least one branch as arrays (q: (k, n), the errors: (k,)); ``make_row(data, i)`` builds the
        i-th result when the set is first indexed or iterated (a solver's row maker, made once, and this set's
        data: nothing is built per call that a reader may never ask for)."""
        made = cls.__new__(cls)
        made.q, made.position_error, made.rotation_error = q, position_error, rotation_error
        made._results, made._make_row, made._data = None, make_row, data
        made.status, made.message, made.method, made.unseen = Status.CONVERGED, "", method, unseen
        made._certify = None
        return made

    def certified_by(self, certify: Callable[[], tuple[str, str]] | tuple[str, str]) -> Branches:
        """This set, its completeness (``complete``, ``complete_reason``) given, or computed by ``certify()`` when
        first read."""
        self._certify = certify
        return self

    @property
    def complete(self) -> Completeness:
        """"certified", "search", "estimate" or "" (see the class)."""
        return Completeness(self._completeness()[0])

    @property
    def complete_reason(self) -> str:
        """Why the set is not certified complete, in words ("" when it is)."""
        return self._completeness()[1]

    def _completeness(self) -> tuple[str, str]:
        if callable(self._certify):
            self._certify = self._certify()
        if self._certify is None:
            self._certify = _BY_METHOD.get(self.method, ("", "how the set was found is not known"))
        return self._certify  # type: ignore[no-any-return]

    def _built(self) -> list[IKResult]:
        if self._results is None:
            make_row, data = self._make_row, self._data
            self._results = [make_row(data, i) for i in range(self.q.shape[0])]
        return self._results

    def __len__(self) -> int:
        return int(self.q.shape[0])

    @overload
    def __getitem__(self, index: int) -> IKResult: ...

    @overload
    def __getitem__(self, index: slice) -> list[IKResult]: ...

    def __getitem__(self, index: int | slice) -> IKResult | list[IKResult]:
        return self._built()[index]

    def __iter__(self) -> Iterator[IKResult]:
        return iter(self._built())

    def __eq__(self, other: object) -> bool:
        """Equal to a list or Branches of the same results (an empty set equals ``[]``)."""
        if not isinstance(other, list | Branches):
            return NotImplemented
        return len(self) == len(other) and list(self) == list(other)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Branches({len(self)} branches, status={self.status.value!r}, method={self.method.value!r})"

    def __getstate__(self) -> dict[str, Any]:
        """The arrays, the results and the completeness, built (a pickle never carries the maker or the
        certifier)."""
        self._built()
        return {**self.__dict__, "_make_row": _called, "_data": None, "_certify": self._completeness()}


_BY_METHOD = {
    "multistart": ("estimate", "seeded starts: unseen estimates the chance that another start finds a new branch"),
    "search": ("search", "the 1-D search is measured complete, not proved (docs/analytic.md)"),
    "sweep": ("search", "every branch at each sampled value of the held joint, not between them"),
    "closed form": ("search", "no certificate was computed for this set"),
    "elimination": ("search", "no certificate was computed for this set"),
}


def _called(make: Callable[[int], IKResult], i: int) -> IKResult:
    """The row maker of a set made by :meth:`Branches.from_arrays`: its ``make(i)``."""
    return make(i)


@dataclass
class Attempt:
    """One solver run from one start, before kinelab's Pinocchio check (internal to the driver).

    ``mode`` names the variant that ran ("frdm (anderson)", "biquat (simple, ...)"); empty: the solver's name.
    """

    q: np.ndarray
    status: Status
    iterations: int
    events: list[SingularEvent] = field(default_factory=list)
    bypasses: list[BypassRecord] = field(default_factory=list)
    diagnostics: Diagnostics = NO_DIAGNOSTICS
    mode: str = ""


@dataclass
class TrackResult:
    """One q per path sample (rows, rad/m) with its Pinocchio-measured errors and the monitor log.

    Attributes:
        q: (K, n) one configuration per sample [rad or m].
        position_error: (K,) [m]; rotation_error: (K,) [rad] (the judge's FK against each sample's target).
        status_code: (K,) int8 codes of :class:`Status` (``status`` gives the members).
        iterations: (K,) the solver's iterations per sample (FRDM sweeps); wall_time: (K,) [s] per sample.
        events, bypasses: the monitor's log (a redundant arm's self-motion events are made when ``events`` is
            first read); mode: how the path was followed; contacts: (sample, Contact) pairs with ``collisions=``.
    """

    q: np.ndarray
    position_error: np.ndarray  # [m]
    rotation_error: np.ndarray  # [rad]
    status_code: np.ndarray
    iterations: np.ndarray
    wall_time: np.ndarray  # [s] per sample
    events: list[SingularEvent] = field(default_factory=list)
    bypasses: list[BypassRecord] = field(default_factory=list)
    mode: str = "frdm (monitored)"
    contacts: list[tuple[int, Any]] = field(default_factory=list)  # (sample, Contact) with collisions=

    def add_events_later(self, make: Callable[[], list[SingularEvent]]) -> None:
        """Append what ``make()`` returns to :attr:`events`, made when the events are first read: a check of the whole
        path whose cost only a reader of the log pays (``make`` must hold copies of what it reads)."""
        made = self.events
        self.__dict__.pop("events")
        self.__dict__["_make_events"] = lambda: made + make()

    def __getstate__(self) -> dict[str, Any]:
        """The fields, events made (a pickle or a copy never carries the maker)."""
        _ = self.events
        return self.__dict__

    @property
    def joint_steps(self) -> np.ndarray:
        """|q_k − q_(k−1)| per sample and joint (first row zero) [rad or m]."""
        return np.vstack([np.zeros(self.q.shape[1]), np.abs(np.diff(self.q, axis=0))])

    @property
    def max_joint_step(self) -> float:
        """The largest joint change between two consecutive samples [rad or m]."""
        return float(self.joint_steps.max())

    @property
    def status(self) -> np.ndarray:
        """(K,) each sample's :class:`Status` member (an object array; ``== "converged"`` works)."""
        return Status.of_codes(self.status_code)

    @property
    def sweeps(self) -> np.ndarray:
        """The same as :attr:`iterations` (this field's earlier name, kept for code that reads it)."""
        return self.iterations

    @property
    def reached(self) -> np.ndarray:
        """Per sample: True when the judge confirms the tolerances within the limits."""
        return np.asarray(self.status_code == Status.CONVERGED.code)

    @property
    def success(self) -> np.ndarray:
        """The same as :attr:`reached` (the name :class:`~kinelab.ik.result.IKResult` uses)."""
        return self.reached

    @property
    def path_success(self) -> bool:
        """True when every sample is reached: met within the limits and not by a jump."""
        return bool(self.reached.all())

    def summary(self) -> dict[str, Any]:
        """Samples, reached, the worst errors and step, monitor counts, the median time per sample."""
        return {
            "samples": len(self.status_code),
            "status": status_counts(self.status_code),
            "reached": int(self.reached.sum()),
            "max_position_error_m": float(self.position_error.max()),
            "max_rotation_error_rad": float(self.rotation_error.max()),
            "max_joint_step": self.max_joint_step,
            "monitor_events": len(self.events),
            "bypasses": len(self.bypasses),
            "median_time_per_sample_s": float(np.median(self.wall_time)),
            "mode": self.mode,
        }


class _LaterEvents:
    """A path's ``events`` made when first read where :meth:`TrackResult.add_events_later` left a maker in the
    instance's dict; the list the dataclass sets shadows this otherwise (a non-data descriptor)."""

    def __get__(self, obj: Any, owner: Any = None) -> Any:
        if obj is None:
            return self
        made: list[SingularEvent] = obj.__dict__.pop("_make_events")()
        obj.__dict__["events"] = made
        return made


TrackResult.events = _LaterEvents()  # type: ignore[assignment]


def status_counts(codes: np.ndarray) -> dict[str, int]:
    """How many rows end in each status, by the status's name, in the order :class:`Status` lists them."""
    counts = np.bincount(np.asarray(codes, dtype=np.intp), minlength=len(_MEMBERS))
    return {str(s): int(c) for s, c in zip(_MEMBERS, counts, strict=True) if c}
