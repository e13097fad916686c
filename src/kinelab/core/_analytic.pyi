from typing import Any

import numpy as np

from kinelab.core._chain import Judge

ROW_NOT_STARTED: int

def branches(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, H: np.ndarray,
             lower: np.ndarray, upper: np.ndarray, ref: np.ndarray, use_ref: bool, same: float, slack: float,
             out: np.ndarray, found: np.ndarray, free: np.ndarray) -> int: ...
def branches_batch(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray,
                   H: np.ndarray, lower: np.ndarray, upper: np.ndarray, same: float, slack: float, out: np.ndarray,
                   found: np.ndarray, free: np.ndarray, count: np.ndarray, threads: int) -> None: ...
def search_errors(kind: int, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, H: np.ndarray,
                  t: np.ndarray, e: np.ndarray, margin: np.ndarray) -> None: ...
def general_roots(general: np.ndarray, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray,
                  H: np.ndarray) -> np.ndarray: ...

class ClosedForm:
    n: int
    def __init__(self, judge: Judge, spec: Any) -> None: ...
    def solve(self, H: np.ndarray, ref: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                                     np.ndarray, int] | None: ...
    def every(self, target: Any, made: Any) -> Any: ...
    def solve_batch(self, H: np.ndarray, q: np.ndarray, errors: np.ndarray, merged: np.ndarray,
                    continuum: np.ndarray, count: np.ndarray, near: np.ndarray, threads: int,
                    deadline: float = ...) -> None: ...
    def nearest_batch(self, H: np.ndarray, refs: np.ndarray, q: np.ndarray, errors: np.ndarray, count: np.ndarray,
                      near: np.ndarray, threads: int, deadline: float = ...) -> None: ...
