"""The serial chain as plain arrays, as every kinelab kernel reads it.

A :class:`ChainModel` is built once per Chain (and dies with it): the joint placements at q = 0, the
local joint axes, the joint kinds and the tool placement, in Pinocchio's terms. The compiled FK
(:func:`chain_fk`, :mod:`kinelab.core._frdm`) turns it into the chain's vectors at any q: unit joint axes e_i
and points o_i on them, the tool point p and tool rotation R, all in the base frame. These are the vector model of the
FRDM paper (docs/methods.md §1.2) and the screws from which the biquaternion solver's A(q) is built
(§2.3, :func:`jacobian_local`). Tests hold every function here against Pinocchio.

Joint kinds: ``REVOLUTE`` (bounded), ``PRISMATIC``, ``CONTINUOUS`` (revolute without limits).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from kinelab.core import _frdm
from kinelab.core._biquat import jacobian_local_of
from kinelab.core._frdm import JointKind
from kinelab.errors import ChainError
from kinelab.robot import Chain
from kinelab.robot.certificate import chain_arrays

REVOLUTE, PRISMATIC, CONTINUOUS = (int(k) for k in (JointKind.REVOLUTE, JointKind.PRISMATIC, JointKind.CONTINUOUS))
KIND_CODES = {"revolute": REVOLUTE, "prismatic": PRISMATIC, "continuous": CONTINUOUS}


class PackedChain(NamedTuple):
    """The arrays the compiled FK reads. Units: m, rad; frames as named."""

    placement_R: np.ndarray  # (n, 3, 3) joint frame in its parent's, at q = 0
    placement_t: np.ndarray  # (n, 3) [m]
    axis_local: np.ndarray  # (n, 3) unit joint axes in the joint frames
    kind: np.ndarray  # (n,) int64 joint codes
    tool_R: np.ndarray  # (3, 3) tool frame in the last joint's frame
    tool_t: np.ndarray  # (3,) [m]


@dataclass(frozen=True)
class ChainModel:
    """A Chain's base → tool chain as arrays, with its limits and its characteristic length."""

    joint_names: tuple[str, ...]
    chain: PackedChain
    lower: np.ndarray  # (n,) limits [rad or m]; continuous joints −inf
    upper: np.ndarray  # (n,) continuous joints +inf
    length: float  # characteristic length L [m] (Chain.characteristic_length)

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


def build(robot: Chain) -> ChainModel:
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
    chain = PackedChain(placement_R=arrays.placement_R, placement_t=arrays.placement_t, axis_local=arrays.axis,
                        kind=kind, tool_R=arrays.tool_R, tool_t=arrays.tool_t)
    lower = np.where(kind == CONTINUOUS, -np.inf, robot.lower).astype(float)
    upper = np.where(kind == CONTINUOUS, np.inf, robot.upper).astype(float)
    return ChainModel(tuple(robot.joint_names), chain, lower, upper, robot.characteristic_length())


def chain_model(robot: Chain) -> ChainModel:
    """The robot's chain model, built on first use and kept on the Chain."""
    return robot.derived("chain_model", build)


def chain_fk(ch: PackedChain, q: np.ndarray, e_out: np.ndarray, o_out: np.ndarray, p_out: np.ndarray,
             R_out: np.ndarray) -> None:
    """FK of the chain ``ch`` at q: joint axes ``e_out`` and origins ``o_out`` (n × 3) and the tool pose (``p_out``
    [m], ``R_out``), all in the base frame, written in place (the compiled kernels' own FK)."""
    _frdm.fk(ch, np.ascontiguousarray(q, dtype=float), e_out, o_out, p_out, R_out)


def jacobian_local(e: np.ndarray, o: np.ndarray, kind: np.ndarray, p: np.ndarray, R: np.ndarray) -> np.ndarray:
    """6 × n tool Jacobian in the tool frame (rows v, ω), from the chain's axes e and points o (n × 3, base frame)
    and the tool pose (p [m], R): the compiled preset's own (:mod:`kinelab.core._biquat`)."""
    return jacobian_local_of(e, o, kind, p, R)
