"""Seed paper 003 (Kapustina 2019, KUKA youBot): the paper's coordinates and the vendor's.

``youbot.urdf`` uses the paper's generalised coordinates Q = (X_C, Y_C, θ, θ1..θ5) directly. The ROS
vendor description (youbot_description) measures the arm joints from other zeros and, for θ1 and θ5,
in the other sense; these helpers convert, in degrees as both sources state them.
"""

from __future__ import annotations

import numpy as np

# theta_i = SIGN_i * q_i + OFFSET_i [deg], for the five arm joints
VENDOR_SIGN = np.array([-1.0, 1.0, 1.0, 1.0, -1.0])
VENDOR_OFFSET_DEG = np.array([169.0, -65.0, 146.0, -102.5, 167.5])

# The paper's joint limits (eq. 1) for θ1..θ5 [deg]
PAPER_LOWER_DEG = np.array([-169.0, -65.0, -151.0, -102.5, -167.5])
PAPER_UPPER_DEG = np.array([169.0, 90.0, 146.0, 102.5, 167.5])


def vendor_to_paper_deg(q_vendor_deg) -> np.ndarray:
    """Vendor arm joint values q1..q5 [deg] → the paper's θ1..θ5 [deg]."""
    return VENDOR_SIGN * np.asarray(q_vendor_deg, dtype=float) + VENDOR_OFFSET_DEG


def paper_to_vendor_deg(theta_deg) -> np.ndarray:
    """The paper's θ1..θ5 [deg] → vendor arm joint values q1..q5 [deg]."""
    return (np.asarray(theta_deg, dtype=float) - VENDOR_OFFSET_DEG) * VENDOR_SIGN
