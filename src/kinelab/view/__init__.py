"""The meshcat view of a robot (:mod:`~kinelab.view.scene`)."""

from kinelab.view.scene import Scene

__all__ = ["Scene"]
