import numpy as np

def candidates(q: np.ndarray, parents: np.ndarray, place_R: np.ndarray, place_t: np.ndarray, axis: np.ndarray,
               kind: np.ndarray, q_index: np.ndarray, joints: np.ndarray, centres: np.ndarray, radii: np.ndarray,
               normals: np.ndarray, pairs: np.ndarray, margin: float, out: np.ndarray) -> int: ...
