"""Locked joints folded into a model (``pin.buildReducedModel``), where a frame bears a locked joint's name."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

NAMESAKE = "\x00namesake"  # appended, while Pinocchio folds the locked joints, to a frame named as a joint is


def reduced(full: pin.Model, lock_ids: list[int], q_ref: np.ndarray,
            geometry: pin.GeometryModel | None = None) -> Any:
    """``pin.buildReducedModel`` of ``full`` (and of ``geometry`` when given: then ``(model, geometry)``), where a
    link or another frame may bear a joint's name (ANYmal C's LF_HAA, a link and its fixed joint in B1's
    gripperStator): Pinocchio looks frames up by name alone while it folds and refuses two. The namesakes are
    renamed while it folds, and named back after.

    Raises:
        ValueError: Pinocchio's, for what it still cannot fold.
    """
    clash = namesakes(full)
    model = pin.Model(full) if clash else full
    for i in clash:
        frame = model.frames[i]
        frame.name = frame.name + NAMESAKE
        model.frames[i] = frame
    out = pin.buildReducedModel(model, lock_ids, q_ref) if geometry is None else \
        pin.buildReducedModel(model, geometry, lock_ids, q_ref)
    built = out if geometry is None else out[0]
    for i, frame in enumerate(built.frames):
        if frame.name.endswith(NAMESAKE):
            frame.name = frame.name[: -len(NAMESAKE)]
            built.frames[i] = frame
    return out


def namesakes(model: pin.Model) -> list[int]:
    """The frames that share their name with another frame, but the one Pinocchio should find by it: a joint's
    frame where there is one, else the first of the name."""
    first: dict[str, int] = {}
    for i, f in enumerate(model.frames):
        if f.name not in first or (f.type == pin.FrameType.JOINT and model.frames[first[f.name]].type
                                   != pin.FrameType.JOINT):
            first[f.name] = i
    return [i for i, f in enumerate(model.frames) if first[f.name] != i]
