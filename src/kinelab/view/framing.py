"""Where the camera stands and where the floor lies, from the points the robot occupies.

meshcat's orbit controls always turn about the viewer's origin, so a view is framed by moving the scene:
the centre of the robot's points goes to the origin, a floor grid sized to the robot is drawn under its
base (meshcat's own 20 m grid is hidden: a scaled copy of it does not draw as a floor), and the camera
backs off along a fixed direction until the sphere holding the robot fits the field of view. All lengths
in metres, in the robot's base frame unless said otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FOV = np.deg2rad(75.0)  # meshcat's default camera: vertical field of view
ELEVATION, AZIMUTH = np.deg2rad(22.0), np.deg2rad(35.0)  # looking down on the robot from its front right
FILL = 0.8  # the sphere holding the robot spans this share of the frame's height
NICE_CELLS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)


@dataclass(frozen=True)
class Framing:
    """The sphere that holds the robot and the height of its floor."""

    centre: np.ndarray  # (3,) [m]: moved to the viewer's origin
    radius: float  # [m]
    floor_z: float  # [m]: the base's height (the floor is drawn there)
    fill: float = FILL  # share of the frame's height the sphere spans (> 1 for a flat spread of copies, whose
    # sphere is mostly empty above the floor)

    @property
    def cell(self) -> float:
        """The floor grid's cell [m]: a round length near a fifth of the radius."""
        return min(NICE_CELLS, key=lambda c: abs(np.log(c / (self.radius / 5.0))))

    def scene_shift(self) -> np.ndarray:
        """4 × 4 transform of the scene root: the centre to the origin."""
        return _translation(-self.centre)

    def floor_segments(self, cells: int = 24) -> np.ndarray:
        """(3, 2·2(cells+1)) end points [m, base frame] of a square grid of ``cells`` × ``cells`` cells of
        ``cell`` metres, centred under the sphere's centre at the floor's height (meshcat LineSegments)."""
        half = cells * self.cell / 2
        ticks = np.linspace(-half, half, cells + 1)
        cx, cy = self.centre[0], self.centre[1]
        ends = []
        for t in ticks:
            ends += [(cx + t, cy - half), (cx + t, cy + half), (cx - half, cy + t), (cx + half, cy + t)]
        xy = np.array(ends).T
        return np.vstack([xy, np.full(xy.shape[1], self.floor_z)])

    def camera_position(self, aspect: float = 4 / 3) -> list[float]:
        """The camera's position in meshcat's camera frame (three.js axes: y up), distance chosen so that
        the sphere fills FILL of the height (or of the width, on a narrow page)."""
        half = FOV / 2 if aspect >= 1 else np.arctan(np.tan(FOV / 2) * aspect)
        distance = self.radius / np.sin(half) / self.fill
        x = distance * np.cos(ELEVATION) * np.cos(AZIMUTH)
        y = distance * np.cos(ELEVATION) * np.sin(AZIMUTH)
        return [float(x), float(distance * np.sin(ELEVATION)), float(y)]  # (x, up, −y) of the base frame


def frame_points(points: np.ndarray, floor_z: float, margin: float, fill: float = FILL) -> Framing:
    """The framing of a robot occupying ``points`` (rows, base frame) standing on the floor at ``floor_z``:
    the centre of their bounding box, the radius of the sphere about it that holds them plus ``margin``
    (the links' thickness)."""
    pts = np.asarray(points, dtype=float)
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
    radius = float(np.max(np.linalg.norm(pts - centre, axis=1))) + margin
    return Framing(centre, max(radius, 0.05), float(floor_z), fill)


def _translation(t: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = t
    return T
