import numpy as np

def fk_batch(placement_R: np.ndarray, placement_t: np.ndarray, axis: np.ndarray, kind: np.ndarray,
             tool_R: np.ndarray, tool_t: np.ndarray, Q: np.ndarray, out: np.ndarray) -> None: ...

class Judge:
    def __init__(self, placement_R: np.ndarray, placement_t: np.ndarray, axis: np.ndarray, kind: np.ndarray,
                 tool_R: np.ndarray, tool_t: np.ndarray) -> None: ...
    def verdict(self, H_target: np.ndarray, q: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                rot_axis: int) -> tuple[float, float, bool]: ...
