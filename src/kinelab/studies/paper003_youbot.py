"""Seed paper 003 (Kapustina 2019, KUKA youBot): the paper's coordinates and the vendor's.

``youbot.urdf`` uses the paper's generalised coordinates Q = (X_C, Y_C, θ, θ1..θ5) directly. The ROS
vendor description (youbot_description) measures the arm joints from other zeros and, for θ1 and θ5,
in the other sense; these helpers convert, in degrees as both sources state them.
"""

from __future__ import annotations

import numpy as np

from kinelab.analysis.singular import analyze

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


# Kapustina's parameters (eq. 2), read off youbot.urdf: the paper's OXY plane is kinelab's odom plane
# (at base_link height), so d1 is the height of the joint-2 axis above it.
PARAMS = {"h": 0.167, "a1": 0.033, "d1": 0.161, "a2": 0.155, "a3": 0.135, "c": 0.2175}


def paper_location(Q, b: int = 1, p: dict | None = None) -> np.ndarray:
    """X(Q) = (X_E, Y_E, Z_E, ψ, θ_E, φ), eq. (2), as published; Q = (X_C, Y_C, θ, θ1..θ5) [m, rad].

    The signs ± of the Euler angles are b = ±1 (the same choice in all three)."""
    p = p or PARAMS
    X, Y, th, t1, t2, t3, t4, t5 = np.asarray(Q, dtype=float)
    s234, c234 = np.sin(t2 + t3 + t4), np.cos(t2 + t3 + t4)
    reach = p["a1"] + p["a2"] * np.sin(t2) + p["a3"] * np.sin(t2 + t3) + p["c"] * s234
    return np.array([
        X + p["h"] * np.cos(th) + np.cos(th + t1) * reach,
        Y + p["h"] * np.sin(th) + np.sin(th + t1) * reach,
        p["d1"] + p["a2"] * np.cos(t2) + p["a3"] * np.cos(t2 + t3) + p["c"] * c234,
        th + t1 + b * np.pi / 2,
        b * (t2 + t3 + t4),
        t5 + b * np.pi / 2,
    ])


def paper_jacobian(Q, b: int = 1, p: dict | None = None) -> np.ndarray:
    """The paper's analytic 6 × 8 J = ∂X/∂Q, entry by entry as published (j13 … j37, b, l)."""
    p = p or PARAMS
    _, _, th, t1, t2, t3, t4, _ = np.asarray(Q, dtype=float)
    a2, a3, c, h = p["a2"], p["a3"], p["c"], p["h"]
    reach = p["a1"] + a2 * np.sin(t2) + a3 * np.sin(t2 + t3) + c * np.sin(t2 + t3 + t4)  # the paper's l
    C, S = np.cos(th + t1), np.sin(th + t1)
    k5 = a2 * np.cos(t2) + a3 * np.cos(t2 + t3) + c * np.cos(t2 + t3 + t4)
    k6 = a3 * np.cos(t2 + t3) + c * np.cos(t2 + t3 + t4)
    k7 = c * np.cos(t2 + t3 + t4)
    J = np.zeros((6, 8))
    J[0] = [1, 0, -h * np.sin(th) - S * reach, -S * reach, C * k5, C * k6, C * k7, 0]
    J[1] = [0, 1, h * np.cos(th) + C * reach, C * reach, S * k5, S * k6, S * k7, 0]
    J[2, 4] = -a2 * np.sin(t2) - a3 * np.sin(t2 + t3) - c * np.sin(t2 + t3 + t4)
    J[2, 5] = -a3 * np.sin(t2 + t3) - c * np.sin(t2 + t3 + t4)
    J[2, 6] = -c * np.sin(t2 + t3 + t4)
    J[3, 2:4] = 1
    J[4, 4:7] = b
    J[5, 7] = 1
    return J


def paper_rank(Q, b: int = 1, rtol: float = 1e-9) -> int:
    """SVD rank of the paper's J (its rows mix m and rad; the platform columns are O(1) in both)."""
    s = np.linalg.svd(paper_jacobian(Q, b), compute_uv=False)
    return int(np.sum(s > rtol * s[0]))


def singular_configuration(rng: np.random.Generator, theta4: float | None = None) -> np.ndarray:
    """A random Q within the limits with θ2 = θ3 = 0 (the paper's singular set, eq. 4)."""
    lo, hi = np.deg2rad(PAPER_LOWER_DEG), np.deg2rad(PAPER_UPPER_DEG)
    arm = rng.uniform(lo, hi)
    arm[1] = arm[2] = 0.0
    if theta4 is not None:
        arm[3] = theta4
    return np.r_[rng.uniform(-2, 2, 2), rng.uniform(-np.pi, np.pi), arm]


def lost_constraint(robot, Q) -> np.ndarray:
    """The constraint w·(v; ω) = 0 that every tool twist obeys at a rank-5 Q (unscaled, base axes at E,
    unit norm): the left singular vector of the vanishing σ with its linear part divided by L."""
    a = analyze(robot, Q)
    if not a.lost_directions:
        raise ValueError("the configuration is not singular")
    u = np.array(a.lost_directions[0].twist)
    w = np.r_[u[:3] / a.length, u[3:]]
    return w / np.linalg.norm(w)
