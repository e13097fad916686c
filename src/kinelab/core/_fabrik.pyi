from typing import Any

import numpy as np

def attempt(chain: Any, lower: np.ndarray, upper: np.ndarray, target: np.ndarray, q: np.ndarray, tol: float,
            max_iterations: int) -> tuple[int, float]: ...
