import numpy as np

def equations(h: np.ndarray, o: np.ndarray, R0: np.ndarray, N0: np.ndarray, scale: float, q: np.ndarray,
              H: np.ndarray, F: np.ndarray, J: np.ndarray) -> None: ...
