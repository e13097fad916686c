"""Closed-form inverses written in the tests from the arms' standard derivations, each checked by Pinocchio's FK
where it is used: the oracles that kinelab's multistart and analytic branches are held against."""

import numpy as np

UR_DH = {"ur5": (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
         "ur10": (0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922)}
BASE = np.diag([-1.0, -1.0, 1.0, 1.0])  # ur_description's base_link is the DH base turned by π about z


def dh(d, a, alpha, theta):
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


def ur_inverse(T, d1, a2, a3, d4, d5, d6):
    """Every real solution (angles in (−π, π]) for the flange pose T in the DH base frame."""
    p5 = T[:3, 3] - d6 * T[:3, 2]  # the wrist centre
    r = np.hypot(p5[0], p5[1])
    out = []
    for s1 in (1, -1):
        if r < abs(d4):
            break
        t1 = np.arctan2(p5[1], p5[0]) + s1 * np.arccos(d4 / r) + np.pi / 2
        c5 = (T[0, 3] * np.sin(t1) - T[1, 3] * np.cos(t1) - d4) / d6
        for s5 in (1, -1):
            if abs(c5) > 1 or abs(np.sin(np.arccos(np.clip(c5, -1, 1)))) < 1e-9:
                continue
            t5 = s5 * np.arccos(c5)
            t6 = np.arctan2((-T[0, 1] * np.sin(t1) + T[1, 1] * np.cos(t1)) / np.sin(t5),
                            (T[0, 0] * np.sin(t1) - T[1, 0] * np.cos(t1)) / np.sin(t5))
            T14 = np.linalg.inv(dh(d1, 0, np.pi / 2, t1)) @ T @ np.linalg.inv(
                dh(d5, 0, -np.pi / 2, t5) @ dh(d6, 0, 0, t6))
            x, y = T14[0, 3], T14[1, 3]
            c3 = (x * x + y * y - a2 * a2 - a3 * a3) / (2 * a2 * a3)
            for s3 in (1, -1):
                if abs(c3) > 1 + 1e-9:  # beyond reach; within 1e-9, a stretched or folded elbow met to rounding
                    continue
                t3 = s3 * np.arccos(np.clip(c3, -1, 1))
                t2 = np.arctan2(y, x) - np.arctan2(a3 * np.sin(t3), a2 + a3 * np.cos(t3))
                T34 = np.linalg.inv(dh(0, a2, 0, t2) @ dh(0, a3, 0, t3)) @ T14
                q = np.array([t1, t2, t3, np.arctan2(T34[1, 0], T34[0, 0]), t5, t6])
                out.append(np.arctan2(np.sin(q), np.cos(q)))
    return out
