"""Numbers drawn in a scene: meshcat has no text, so a number is drawn as seven-segment strokes (thin cylinders)
in an upright plane that faces the page's camera (:mod:`kinelab.view.framing`'s fixed direction), read left to
right from where the page opens."""

from __future__ import annotations

from typing import TYPE_CHECKING

import meshcat.geometry as g
import numpy as np
import pinocchio as pin

from kinelab.view.framing import AZIMUTH

if TYPE_CHECKING:
    import meshcat

# a digit's segments as (x0, y0, x1, y1) in a cell one wide and two high, origin at its lower left
STROKES = {"a": (0, 2, 1, 2), "b": (1, 2, 1, 1), "c": (1, 1, 1, 0), "d": (0, 0, 1, 0), "e": (0, 1, 0, 0),
           "f": (0, 2, 0, 1), "g": (0, 1, 1, 1)}
LIT = {"0": "abcdef", "1": "bc", "2": "abged", "3": "abgcd", "4": "fgbc", "5": "afgcd", "6": "afgedc", "7": "abc",
       "8": "abcdefg", "9": "abcdfg"}


def right_of_camera() -> np.ndarray:
    """The unit horizontal direction (base frame) that runs left to right on the page as it opens: the camera
    looks from (cos A, −sin A, ·), so its right is ẑ × that, flattened (framing's azimuth A)."""
    toward = np.array([np.cos(AZIMUTH), -np.sin(AZIMUTH), 0.0])
    return np.cross([0.0, 0.0, 1.0], toward)


def draw_number(node: meshcat.Visualizer, text: str, centre: np.ndarray, height: float, colour: int) -> None:
    """The digits of ``text`` under the meshcat ``node``, their block centred at ``centre`` [m, base frame],
    ``height`` [m] tall, upright and facing the camera.

    Raises:
        ValueError: ``text`` holds a character that is not a digit.
    """
    if not text.isdigit():
        raise ValueError(f"draw_number draws digits only, got {text!r}")
    cell, gap = height / 2, 0.5 * height / 2  # a digit is half as wide as tall, a gap of half a digit between
    right, up = right_of_camera(), np.array([0.0, 0.0, 1.0])
    width = len(text) * cell + (len(text) - 1) * gap
    origin = np.asarray(centre, dtype=float) - 0.5 * width * right - 0.5 * height * up
    radius = 0.09 * height
    material = g.MeshLambertMaterial(color=colour)
    for i, digit in enumerate(text):
        left = origin + i * (cell + gap) * right
        for segment in LIT[digit]:
            x0, y0, x1, y1 = STROKES[segment]
            a, b = left + cell * (x0 * right + y0 * up), left + cell * (x1 * right + y1 * up)
            node[f"{i}{segment}"].set_object(g.Cylinder(cell, radius), material)
            turn = pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), (b - a) / cell).matrix()
            node[f"{i}{segment}"].set_transform(pin.SE3(turn, (a + b) / 2).homogeneous)
