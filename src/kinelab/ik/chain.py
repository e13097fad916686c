"""The serial chain as plain arrays, and the compiled kinematics every kinelab kernel shares.

A :class:`ChainModel` is built once per Robot (and dies with it): the joint placements at q = 0, the
local joint axes, the joint kinds and the tool placement, in Pinocchio's terms. The compiled FK
(:func:`chain_fk`) turns it into the chain's vectors at any q: unit joint axes e_i and points o_i on
them, the tool point p and tool rotation R, all in the base frame. These are the vector model of the
FRDM paper (docs/methods.md §1.2) and the screws from which the biquaternion solver's A(q) is built
(§2.3, :func:`jacobian_local`). Tests hold every function here against Pinocchio.

Joint kinds: ``REVOLUTE`` (bounded), ``PRISMATIC``, ``CONTINUOUS`` (revolute without limits).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from kinelab.errors import ChainError
from kinelab.geometry import TWO_PI
from kinelab.robot import Robot
from kinelab.robot.certificate import chain_arrays

REVOLUTE, PRISMATIC, CONTINUOUS = 0, 1, 2
KIND_CODES = {"revolute": REVOLUTE, "prismatic": PRISMATIC, "continuous": CONTINUOUS}


class Chain(NamedTuple):
    """The arrays the compiled FK reads (a numba-typed tuple). Units: m, rad; frames as named."""

    placement_R: np.ndarray  # (n, 3, 3) joint frame in its parent's, at q = 0
    placement_t: np.ndarray  # (n, 3) [m]
    axis_local: np.ndarray  # (n, 3) unit joint axes in the joint frames
    kind: np.ndarray  # (n,) int64 joint codes
    tool_R: np.ndarray  # (3, 3) tool frame in the last joint's frame
    tool_t: np.ndarray  # (3,) [m]


@dataclass(frozen=True)
class ChainModel:
    """A Robot's base → tool chain as arrays, with its limits and its characteristic length."""

    joint_names: tuple[str, ...]
    chain: Chain
    lower: np.ndarray  # (n,) limits [rad or m]; continuous joints −inf
    upper: np.ndarray  # (n,) continuous joints +inf
    length: float  # characteristic length L [m] (Robot.characteristic_length)

    @property
    def n(self) -> int:
        """Number of chain joints."""
        return len(self.joint_names)

    @property
    def kind(self) -> np.ndarray:
        """Joint codes, (n,)."""
        return self.chain.kind

    @property
    def limits(self) -> np.ndarray:
        """L(2, n): first row lower, second row upper limits (the FRDM paper's notation)."""
        return np.vstack([self.lower, self.upper])

    def vectors(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """The chain's vectors at q (base frame; the FRDM paper's vector model, docs/methods.md §1.2).

        Args:
            q: one number per joint [rad or m].

        Returns:
            ``e`` (n × 3) unit axes, ``o`` (n × 3) points on them [m], ``p`` type flags (1 revolute,
            0 prismatic), ``M`` link vectors (o_{i+1} − o_i and N − o_n) [m], ``N`` the tool point [m],
            ``u_x``, ``u_y``, ``u_z`` the tool axes and ``R`` the tool rotation.
        """
        q = np.asarray(q, dtype=float)
        e, o, p, R = np.empty((self.n, 3)), np.empty((self.n, 3)), np.empty(3), np.empty((3, 3))
        chain_fk(self.chain, q, e, o, p, R)
        links = np.vstack([np.diff(o, axis=0), p - o[-1]])
        return {"e": e, "o": o, "p": (self.kind != PRISMATIC).astype(int), "M": links, "N": p,
                "u_x": R[:, 0], "u_y": R[:, 1], "u_z": R[:, 2], "R": R}


def build(robot: Robot) -> ChainModel:
    """The chain model of ``robot`` (every joint 1-DoF and in series: checked here).

    Raises:
        ChainError: a joint not in series with the previous one, a tool frame not on the last joint, or a
            mimic joint (these kernels step one coordinate at a time about its own axis).
    """
    if robot.mimics:
        mimic = next(iter(robot.mimics.values()))
        raise ChainError(f"{robot.name}: joint {mimic.name!r} mimics {mimic.leader!r}; the FRDM and biquaternion "
                         "kernels turn one joint at a time and do not model coupled joints: use solver='dls' "
                         "(Pinocchio's model couples them)")
    arrays = chain_arrays(robot)  # the same packing as the certified judge's
    if isinstance(arrays, str):
        raise ChainError(f"{robot.name}: {arrays}")
    kind = np.array([KIND_CODES[k] for k in robot.joint_kinds], dtype=np.int64)
    chain = Chain(placement_R=arrays.placement_R, placement_t=arrays.placement_t, axis_local=arrays.axis, kind=kind,
                  tool_R=arrays.tool_R, tool_t=arrays.tool_t)
    lower = np.where(kind == CONTINUOUS, -np.inf, robot.lower).astype(float)
    upper = np.where(kind == CONTINUOUS, np.inf, robot.upper).astype(float)
    return ChainModel(tuple(robot.joint_names), chain, lower, upper, robot.characteristic_length())


def chain_model(robot: Robot) -> ChainModel:
    """The robot's chain model, built on first use and kept on the Robot."""
    return robot.derived("chain_model", build)


@njit(cache=True, inline="always")
def rotm(x, y, z, angle):
    """Rodrigues' rotation by ``angle`` [rad] about the unit vector (x, y, z), as 9 scalars row by row."""
    c, s = np.cos(angle), np.sin(angle)
    C = 1.0 - c
    return (c + x * x * C, x * y * C - z * s, x * z * C + y * s,
            y * x * C + z * s, c + y * y * C, y * z * C - x * s,
            z * x * C - y * s, z * y * C + x * s, c + z * z * C)


@njit(cache=True)
def rot(axis, angle):
    """Rotation matrix by ``angle`` [rad] about the unit vector ``axis``."""
    m = rotm(axis[0], axis[1], axis[2], angle)
    R = np.empty((3, 3))
    for k in range(9):
        R[k // 3, k % 3] = m[k]
    return R


@njit(cache=True, inline="always")
def mm_into(A, B, out):
    """out = A @ B for 3 × 3 matrices (loops: numba's @ calls BLAS, far slower at this size)."""
    for r in range(3):
        a0, a1, a2 = A[r, 0], A[r, 1], A[r, 2]
        for c in range(3):
            out[r, c] = a0 * B[0, c] + a1 * B[1, c] + a2 * B[2, c]


@njit(cache=True, inline="always")
def rotate_rows(m, R):
    """R ← M R in place, M given as 9 scalars."""
    for c in range(3):
        x, y, z = R[0, c], R[1, c], R[2, c]
        R[0, c] = m[0] * x + m[1] * y + m[2] * z
        R[1, c] = m[3] * x + m[4] * y + m[5] * z
        R[2, c] = m[6] * x + m[7] * y + m[8] * z


@njit(cache=True, inline="always")
def rotate_about(m, ox, oy, oz, v):
    """v ← o + M (v − o) in place."""
    x, y, z = v[0] - ox, v[1] - oy, v[2] - oz
    v[0] = ox + m[0] * x + m[1] * y + m[2] * z
    v[1] = oy + m[3] * x + m[4] * y + m[5] * z
    v[2] = oz + m[6] * x + m[7] * y + m[8] * z


@njit(cache=True)
def chain_fk(ch, q, e_out, o_out, p_out, R_out):
    """FK of the chain ``ch`` (a :class:`Chain`) at q: joint axes ``e_out`` and origins ``o_out`` (n × 3) and
    the tool pose (``p_out`` [m], ``R_out``), all in the base frame, written in place."""
    PR, Pt, axis, kind, TR, Tt = ch.placement_R, ch.placement_t, ch.axis_local, ch.kind, ch.tool_R, ch.tool_t
    Rw = np.eye(3)
    tmp = np.empty((3, 3))
    t0 = t1 = t2 = 0.0
    for i in range(q.shape[0]):
        P = Pt[i]
        t0, t1, t2 = (t0 + Rw[0, 0] * P[0] + Rw[0, 1] * P[1] + Rw[0, 2] * P[2],
                      t1 + Rw[1, 0] * P[0] + Rw[1, 1] * P[1] + Rw[1, 2] * P[2],
                      t2 + Rw[2, 0] * P[0] + Rw[2, 1] * P[1] + Rw[2, 2] * P[2])
        mm_into(Rw, PR[i], tmp)
        a = axis[i]
        e0 = tmp[0, 0] * a[0] + tmp[0, 1] * a[1] + tmp[0, 2] * a[2]
        e1 = tmp[1, 0] * a[0] + tmp[1, 1] * a[1] + tmp[1, 2] * a[2]
        e2 = tmp[2, 0] * a[0] + tmp[2, 1] * a[1] + tmp[2, 2] * a[2]
        if kind[i] == PRISMATIC:
            t0, t1, t2 = t0 + e0 * q[i], t1 + e1 * q[i], t2 + e2 * q[i]
            Rw[:, :] = tmp
        else:
            # Rw ← tmp·Rot(a, q) about the exact unit local axis: the world axis e carries rounding, and a
            # rotation about it would feed that back into Rw and grow along a long chain
            m = rotm(a[0], a[1], a[2], q[i])
            for r in range(3):
                x, y, z = tmp[r, 0], tmp[r, 1], tmp[r, 2]
                Rw[r, 0] = x * m[0] + y * m[3] + z * m[6]
                Rw[r, 1] = x * m[1] + y * m[4] + z * m[7]
                Rw[r, 2] = x * m[2] + y * m[5] + z * m[8]
        e_out[i, 0], e_out[i, 1], e_out[i, 2] = e0, e1, e2
        o_out[i, 0], o_out[i, 1], o_out[i, 2] = t0, t1, t2
    for r in range(3):
        p_out[r] = (t0, t1, t2)[r] + Rw[r, 0] * Tt[0] + Rw[r, 1] * Tt[1] + Rw[r, 2] * Tt[2]
    mm_into(Rw, TR, R_out)


@njit(cache=True)
def rotation_angle(R, Rstar):
    """Angle [rad] of R*ᵀR, accurate near 0 and near π (atan2 of the sine and cosine parts)."""
    M = np.empty((3, 3))
    mm_into(Rstar.T, R, M)
    sx = 0.5 * (M[2, 1] - M[1, 2])
    sy = 0.5 * (M[0, 2] - M[2, 0])
    sz = 0.5 * (M[1, 0] - M[0, 1])
    c = 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)
    return np.arctan2(np.sqrt(sx * sx + sy * sy + sz * sz), c)


@njit(cache=True)
def xorshift_uniform(state):
    """xorshift64*: a small seeded generator for restarts inside the kernel; returns a float in [0, 1)."""
    x = state[0]
    x ^= x >> np.uint64(12)
    x ^= x << np.uint64(25)
    x ^= x >> np.uint64(27)
    state[0] = x
    return float((x * np.uint64(2685821657736338717)) >> np.uint64(11)) / 9007199254740992.0


@njit(cache=True)
def quat_wxyz(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix, w ≥ 0 (Shepperd)."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    q = np.empty(4)
    if t > 0.0:
        s = np.sqrt(t + 1.0) * 2.0
        q[0] = 0.25 * s
        q[1] = (R[2, 1] - R[1, 2]) / s
        q[2] = (R[0, 2] - R[2, 0]) / s
        q[3] = (R[1, 0] - R[0, 1]) / s
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2]) * 2.0
        q[0] = (R[2, 1] - R[1, 2]) / s
        q[1] = 0.25 * s
        q[2] = (R[0, 1] + R[1, 0]) / s
        q[3] = (R[0, 2] + R[2, 0]) / s
    elif R[1, 1] > R[2, 2]:
        s = np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2]) * 2.0
        q[0] = (R[0, 2] - R[2, 0]) / s
        q[1] = (R[0, 1] + R[1, 0]) / s
        q[2] = 0.25 * s
        q[3] = (R[1, 2] + R[2, 1]) / s
    else:
        s = np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1]) * 2.0
        q[0] = (R[1, 0] - R[0, 1]) / s
        q[1] = (R[0, 2] + R[2, 0]) / s
        q[2] = (R[1, 2] + R[2, 1]) / s
        q[3] = 0.25 * s
    if q[0] < 0.0:
        q = -q
    return q / np.sqrt(q @ q)


@njit(cache=True)
def jacobian_local(e, o, kind, p, R):
    """6 × n tool Jacobian in the tool frame (rows v, ω), from the chain's axes and points."""
    n = e.shape[0]
    J = np.empty((6, n))
    for i in range(n):
        if kind[i] == PRISMATIC:
            v = e[i]
            w = np.zeros(3)
        else:
            r = p - o[i]
            v = np.cross(e[i], r)
            w = e[i]
        J[:3, i] = R.T @ v
        J[3:, i] = R.T @ w
    return J


@njit(cache=True)
def wrap_into_limits(q, kind, lower, upper):
    """Wrap revolute joints by 2πk into their limits, continuous ones into (−π, π]; True if all fit."""
    ok = True
    for i in range(q.shape[0]):
        if kind[i] == CONTINUOUS:
            q[i] = np.arctan2(np.sin(q[i]), np.cos(q[i]))
        elif kind[i] != PRISMATIC and (q[i] < lower[i] or q[i] > upper[i]):
            shifted = q[i] + TWO_PI * np.ceil((lower[i] - q[i]) / TWO_PI)
            if shifted <= upper[i]:
                q[i] = shifted
        if kind[i] != CONTINUOUS and (q[i] < lower[i] - 1e-9 or q[i] > upper[i] + 1e-9):
            ok = False
    return ok




@njit(cache=True)
def random_configuration(q, kind, lower, upper, rng_state):
    """q ← a seeded uniform configuration within the limits. A joint without a finite window (continuous, or
    any joint of a solve with ``use_limits=False``) draws on [−π, π) when it turns and keeps its value when it
    slides: there is no range to draw a length from, and a draw between infinite limits is NaN."""
    for i in range(q.shape[0]):
        u = xorshift_uniform(rng_state)
        if np.isfinite(lower[i]) and np.isfinite(upper[i]) and kind[i] != CONTINUOUS:
            q[i] = lower[i] + (upper[i] - lower[i]) * u
        elif kind[i] != PRISMATIC:
            q[i] = -np.pi + TWO_PI * u
