from typing import Any

import numpy as np

def follow(Q: np.ndarray, q0: np.ndarray, chain: Any, objective: Any, pstars: np.ndarray, Rstars: np.ndarray,
           settings: Any, order: int, max_sweeps: int, w_rest: float, rest_sweeps: int, centre: np.ndarray,
           pull: float, lm_iterations: int, rng_state: np.ndarray, deadline: float, codes: np.ndarray,
           sweeps: np.ndarray, toward: np.ndarray | None = None, pace: float = 0.0) -> None: ...
def pose_between_of(p0: np.ndarray, R0: np.ndarray, p1: np.ndarray, R1: np.ndarray, s: float, p_out: np.ndarray,
                    R_out: np.ndarray) -> None: ...
