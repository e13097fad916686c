from enum import IntEnum
from typing import Any

import numpy as np

class JointKind(IntEnum):
    REVOLUTE = 0
    PRISMATIC = 1
    CONTINUOUS = 2

class Order(IntEnum):
    TIP_TO_BASE = 0
    BASE_TO_TIP = 1
    ALTERNATE = 2
    MIXED = 3

class Code(IntEnum):
    CONVERGED = 0
    STALL_STEP = 1
    STALL_WINDOW = 2
    BUDGET = 3
    SINGULAR = 4
    MAX_STEPS = 5
    OUTSIDE_LIMITS = 6
    NOT_STARTED = -2
    STOPPED = -3

class Packed:
    n: int
    def __init__(self, chain: Any, objective: Any, settings: Any, memory: Any = ...) -> None: ...
    def run(self, q: np.ndarray, order: int, max_sweeps: int) -> tuple[int, int]: ...
    def multistart(self, q: np.ndarray, order: int, max_sweeps: int, rng_state: np.ndarray, max_attempts: int,
                   sweep_budget: float, best_q: np.ndarray, stats: np.ndarray) -> int: ...
    def solve(self, q: np.ndarray, order: int, max_sweeps: int, rng_state: np.ndarray, attempts: int,
              first_chunk: float, later_chunk: float, deadline: float, best_q: np.ndarray,
              stats: np.ndarray) -> int: ...

def run_kernel(q: np.ndarray, chain: Any, objective: Any, settings: Any, order: int, max_sweeps: int,
               memory: Any) -> tuple[int, int]: ...
def fk(chain: Any, q: np.ndarray, e: np.ndarray, o: np.ndarray, p: np.ndarray, R: np.ndarray) -> None: ...
def draw_configuration(q: np.ndarray, kind: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                       rng_state: np.ndarray) -> None: ...
def solve_rows(Q: np.ndarray, draw_start: bool, chain: Any, objective: Any, pstars: np.ndarray, Rstars: np.ndarray,
               settings: Any, order: int, max_sweeps: int, rng_states: np.ndarray, attempts: np.ndarray,
               first_chunk: float, later_chunk: float, deadline: float, codes: np.ndarray, stats: np.ndarray,
               threads: int) -> None: ...
def revolute_bc(e: np.ndarray, o: np.ndarray, p: np.ndarray, R: np.ndarray, pstar: np.ndarray, Rstar: np.ndarray,
                w_p: float, w_ax: np.ndarray) -> tuple[float, float]: ...
def sweep_once(q: np.ndarray, e: np.ndarray, o: np.ndarray, kind: np.ndarray, lower: np.ndarray, upper: np.ndarray,
               free: np.ndarray, p: np.ndarray, R: np.ndarray, pstar: np.ndarray, Rstar: np.ndarray, w_p: float,
               w_ax: np.ndarray, relax: float, base_to_tip: bool, q_rest: np.ndarray, w_rest: float) -> float: ...
def pack_chain(chain: Any) -> Packed: ...
def windows_of(chain: Any, q: np.ndarray, pstar: np.ndarray, lower: np.ndarray, upper: np.ndarray, wide: np.ndarray,
               length: float) -> tuple[np.ndarray, np.ndarray]: ...
