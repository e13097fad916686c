"""Analyses of a Chain at one or many configurations.

- :mod:`~kinelab.analysis.singular`: the singularity picture at one configuration.
- :mod:`~kinelab.analysis.families`: sweeps, refinement onto the singular set, families.
- :mod:`~kinelab.analysis.oracles`: independent references (yourdfpy FK, finite-difference Jacobians).
"""
