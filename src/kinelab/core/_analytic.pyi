import numpy as np

def branches(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, H: np.ndarray,
             lower: np.ndarray, upper: np.ndarray, ref: np.ndarray, use_ref: bool, same: float, slack: float,
             out: np.ndarray, found: np.ndarray, free: np.ndarray) -> int: ...
def branches_batch(kind: int, mirrored: bool, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray,
                   H: np.ndarray, lower: np.ndarray, upper: np.ndarray, same: float, slack: float, out: np.ndarray,
                   found: np.ndarray, free: np.ndarray, count: np.ndarray, threads: int) -> None: ...
def search_errors(kind: int, h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, H: np.ndarray,
                  t: np.ndarray, e: np.ndarray, margin: np.ndarray) -> None: ...
