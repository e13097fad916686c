"""The compiled engine's specs, where the IK layer names them (they live with the engine: :mod:`kinelab.core.spec`)."""

from kinelab.core.spec import BiquatSpec, Decline, EngineSpec, FRDMSpec

__all__ = ["BiquatSpec", "Decline", "EngineSpec", "FRDMSpec"]
