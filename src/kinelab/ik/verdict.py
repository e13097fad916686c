"""The checks a solve makes on its target and on its answer (compiled: :mod:`kinelab.core._verdict`).

Pinocchio computes the tool pose; these functions only compare matrices.
"""

from __future__ import annotations

from kinelab.core._verdict import (
    NOT_A_ROTATION,
    NOT_FINITE,
    NOT_HOMOGENEOUS,
    first_defect,
    pose_defect,
    pose_verdict,
    usual_inputs,
)

__all__ = ["NOT_A_ROTATION", "NOT_FINITE", "NOT_HOMOGENEOUS", "first_defect", "pose_defect", "pose_verdict",
           "usual_inputs"]
