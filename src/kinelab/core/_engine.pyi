from typing import Any

from kinelab.core._chain import Judge
from kinelab.core._frdm import Packed

SEED_LIMIT: int

class Engine:
    def __init__(self, judge: Judge, spec: Any) -> None: ...
    def solve(self, target: Any, q0: Any, seed: Any) -> Any: ...

class FRDMEngine(Engine):
    def __init__(self, packed: Packed, judge: Judge, spec: Any) -> None: ...

class BiquatEngine(Engine):
    def __init__(self, packed: Packed, judge: Judge, spec: Any) -> None: ...
