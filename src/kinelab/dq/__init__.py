"""Biquaternions (dual quaternions): the algebra (:mod:`~kinelab.dq.algebra`) and the kinematics of a
chain written with them, Λ(q) and A(q) of paper 001 (:mod:`~kinelab.dq.kinematics`)."""

from kinelab.dq.algebra import DualQuat, same_pose

__all__ = ["DualQuat", "same_pose"]
