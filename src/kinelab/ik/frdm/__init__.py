"""FRDM, the finite rotation and displacement method (Danilov et al.): see methods.md §1.

- :mod:`~kinelab.ik.frdm.model`: the vector model of a chain (build it, inspect it).
- :mod:`~kinelab.ik.frdm.kernel`: the compiled steps, sweeps and acceleration.
- :mod:`~kinelab.ik.frdm.reference`: the same steps written plainly, on Pinocchio's FK.
- :mod:`~kinelab.ik.frdm.solver`: one solve with the singularity monitor and the bypass policy.
- :mod:`~kinelab.ik.frdm.tracking`: following a Cartesian path, warm-started.
"""
