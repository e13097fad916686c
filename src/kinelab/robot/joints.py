"""The joint records of a chain: :class:`Joint` (one coordinate) and :class:`Mimic` (a follower)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Joint:
    """One chain joint: ``kind`` is revolute, prismatic or continuous; limits in rad or m."""

    name: str
    kind: str
    lower: float
    upper: float
    idx_q: int  # first index in Pinocchio's q
    idx_v: int  # index in Pinocchio's v (and Jacobian column)
    axis_local: tuple[float, float, float]

    @property
    def unit(self) -> str:
        """The joint's unit: "m" for a prismatic joint, "rad" otherwise."""
        return "m" if self.kind == "prismatic" else "rad"


@dataclass(frozen=True)
class Mimic:
    """A chain joint that follows another: q_follower = multiplier · q_leader + offset (rad or m)."""

    name: str
    leader: str
    multiplier: float
    offset: float
    lower: float  # the follower's own limits
    upper: float
