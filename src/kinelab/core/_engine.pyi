from typing import Any, TypeVar

from kinelab.core._chain import Judge
from kinelab.core._frdm import Packed
from kinelab.core.spec import BiquatSpec, EngineSpec, FRDMSpec

R = TypeVar("R")

SEED_LIMIT: int
DECLINE_TARGET: int
DECLINE_START: int
DECLINE_OUTSIDE: int
DECLINE_SEED: int
DECLINE_EMPTY: int

def fast_result(cls: type[R], shared: dict[str, Any], values: dict[str, Any]) -> R: ...

class Engine:
    def __init__(self, judge: Judge, spec: EngineSpec) -> None: ...
    def solve(self, target: Any, q0: Any, seed: Any) -> Any: ...

class FRDMEngine(Engine):
    def __init__(self, packed: Packed, judge: Judge, spec: FRDMSpec) -> None: ...

class BiquatEngine(Engine):
    def __init__(self, packed: Packed, judge: Judge, spec: BiquatSpec) -> None: ...
