import numpy as np

def fk_batch(placement_R: np.ndarray, placement_t: np.ndarray, axis: np.ndarray, kind: np.ndarray,
             tool_R: np.ndarray, tool_t: np.ndarray, Q: np.ndarray, out: np.ndarray) -> None: ...
