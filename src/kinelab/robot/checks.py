"""The checks of a chain's configurations: what :class:`~kinelab.robot.chain.Chain` refuses (a wrong shape, a
non-real type, NaN or ±inf, a value outside its joint's limits), each error naming the joint, the value and what
is valid. The chain's methods keep their fast paths for a plain q and call these for everything else."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from kinelab.errors import ConfigurationError, JointLimitError, SRDFError, count_of

if TYPE_CHECKING:
    from kinelab.robot import Chain  # the package (chain.py imports this module)


def named_configuration(chain: Chain, name: str) -> np.ndarray:
    """:meth:`Chain.named_q`: the SRDF's named configuration ``name`` as the chain's q [rad or m]."""
    if chain.srdf is None:
        raise SRDFError(f"{chain.name} was loaded without an SRDF: load(..., srdf=PATH) to use named "
                        "configurations")
    values = chain.srdf.state(name)
    missing = [j for j in chain.joint_names if j not in values]
    if missing:
        raise SRDFError(f"{chain.srdf.path.name}: configuration {name!r} gives no value for chain joint "
                        f"{missing[0]!r}")
    return chain.check_q([values[j] for j in chain.joint_names], limits=True,
                         what=f"{chain.srdf.path.name}'s configuration {name!r}")


def real_values(chain: Chain, q: ArrayLike, what: str) -> np.ndarray:
    """``q`` as n floats (NaN and ±inf kept); ConfigurationError for another shape or a non-real type."""
    try:
        raw = np.asarray(q)
        if raw.dtype.kind not in "fiu":
            raise TypeError
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be {chain.n} numbers (real), got {q!r}") from None
    if raw.shape != (chain.n,):
        raise ConfigurationError(f"{what} must have {chain.n} numbers ({', '.join(chain.joint_names)}) for "
                                 f"{chain.name}, got {count_of(raw.shape)}")
    return raw.astype(float)


def checked_q(chain: Chain, q: ArrayLike, limits: bool, what: str) -> np.ndarray:
    """:meth:`Chain.check_q` past its fast path: ``q`` as n finite floats, within the limits when ``limits``, or the
    error naming the first bad value."""
    try:
        raw = q if type(q) is np.ndarray else np.asarray(q)
        if raw.dtype.kind not in "fiu":  # complex, bool, text and objects are not joint values
            raise TypeError
        arr = raw if raw.dtype == np.float64 else raw.astype(float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"{what} must be {chain.n} numbers (real), got {q!r}") from None
    if arr.shape != (chain.n,):
        raise ConfigurationError(
            f"{what} must have {chain.n} numbers ({', '.join(chain.joint_names)}) for {chain.name}, "
            f"got {count_of(arr.shape)}"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ConfigurationError(f"{what}[{i}] ({chain.joint_names[i]}) is {arr[i]}: values must be finite")
    if limits:
        lower, upper = chain.check_bounds  # the limits widened by LIMIT_SLACK, ∓inf for continuous joints
        outside = (arr < lower) | (arr > upper)
        if outside.any():
            i = int(np.flatnonzero(outside)[0])
            j = chain.joints[i]
            raise JointLimitError(j.name, arr[i], j.lower, j.upper, j.unit)
    return np.ascontiguousarray(arr)


def outside_lines(chain: Chain, q: ArrayLike) -> list[str]:
    """:meth:`Chain.outside_limits`: a line per joint of ``q`` outside its limits."""
    values = np.asarray(q, dtype=float)
    lower, upper = chain.check_bounds
    return [f"{j.name} = {v:g} {j.unit} is outside its limits [{j.lower:.4g}, {j.upper:.4g}] {j.unit}"
            for j, v, lo, hi in zip(chain.joints, values.tolist(), lower, upper, strict=True) if not lo <= v <= hi]


def rows_within(chain: Chain, Q: np.ndarray) -> np.ndarray:
    """:meth:`Chain.within_limits_batch`: per row of (B, n) configurations, within the limits."""
    arr = np.asarray(Q) if not isinstance(Q, np.ndarray) else Q
    if arr.dtype.kind not in "fiu" or arr.ndim != 2 or arr.shape[1] != chain.n:
        raise ConfigurationError(f"Q must be a (B, {chain.n}) array of numbers for {chain.name}, got "
                                 f"{getattr(arr, 'shape', '?')} of {arr.dtype}")
    Q = arr.astype(float, copy=False)
    lower, upper = chain.check_bounds
    inside: np.ndarray = (lower <= Q) & (upper >= Q)
    return np.asarray(inside.all(axis=1))


def checked_rows(chain: Chain, Q: np.ndarray, what: str) -> np.ndarray:
    """:meth:`Chain.check_qs`: Q as (B, n) finite floats, the first bad row named."""
    arr = np.asarray(Q) if not isinstance(Q, np.ndarray) else Q
    if arr.dtype.kind not in "fiu" or arr.ndim != 2 or arr.shape[1] != chain.n:
        raise ConfigurationError(f"{what} must be a (B, {chain.n}) array of numbers for {chain.name}, "
                                 f"got {getattr(arr, 'shape', '?')} of {arr.dtype}")
    arr = np.asarray(arr, dtype=float)
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        b = int(np.flatnonzero(bad)[0])
        chain.check_q(arr[b], what=f"{what}[{b}]")
    return arr
