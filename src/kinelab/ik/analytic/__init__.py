"""Inverse kinematics in closed form for the arms whose geometry allows it: class detection
(:mod:`~kinelab.ik.analytic.classify`), the compiled subproblems and branch kernels, and every branch of a pose
confirmed by Pinocchio (:mod:`~kinelab.ik.analytic.branches`); 7R arms by a swept end joint
(:mod:`~kinelab.ik.analytic.redundancy`)."""
