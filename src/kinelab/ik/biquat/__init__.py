"""Biquaternion kinematic control (paper 001).

Reference: Lomovtseva E.I., Chelnokov Yu.N. Dual matrix and biquaternion methods of solving direct and
inverse kinematics problems of manipulators, for example Stanford robot arm. II. *Izvestiya of Saratov
University. New Series. Series: Mathematics. Mechanics. Informatics*, 2014, vol. 14, iss. 1. The method
after Chelnokov Yu.N. (2013). Method notes: ``docs/methods.md`` §2.

| paper section / equation | kinelab |
|---|---|
| pose Λ = Λ1(q1)∘…∘Λ6(q6) (eq. 3–4) | :func:`kinelab.dq.kinematics.pose` |
| error biquaternion M* = N̄∘Λ (eq. 5) | ``laws.error_biquaternion`` |
| q̇ = A(q)⁻¹U, ω and v on end-link axes (eq. 8) | A: ``chain.jacobian_local``; A⁻¹U: ``laws.joint_rates`` |
| law (9)/(16), K = k + s k0, separate gains | ``laws.simple_law`` |
| law (11)/(12), regular, 2Ṫ = K(scal − T) | ``laws.regular_law`` |
| the Cauchy problem, h = 0.01 s | ``integrators`` (Python), ``kernel`` (compiled preset) |
| the Stanford example (target N, start, M0 = −1) | :mod:`kinelab.studies.paper001_stanford` |

Which A(q): both paths use the LOCAL tool Jacobian [v; ω] of :func:`kinelab.ik.chain.jacobian_local`
(built from the chain's axes and points). Eq. (8) orders the rows [ω; v]; otherwise it is the same
matrix: each column is the joint's unit screw carried to the end-link frame. The biquaternion form of
eq. (8) is :func:`kinelab.dq.kinematics.a_matrix`; the tests hold the three (it, this Jacobian, and
Pinocchio's LOCAL Jacobian) equal to 1e-12.

Modules: ``options`` (BiquatOptions), ``laws`` (the equations, compiled and callable from Python),
``integrators`` (Python: Euler, RK4, adaptive), ``kernel`` (the compiled preset), ``solver``.
"""

from kinelab.ik.biquat import solver
from kinelab.ik.biquat.options import BiquatOptions

__all__ = ["BiquatOptions", "solver"]
