import numpy as np

NOT_FINITE: int
NOT_A_ROTATION: int
NOT_HOMOGENEOUS: int
OK: int
NOT_USUAL: int

def pose_defect(H: np.ndarray) -> int: ...
def first_defect(H: np.ndarray) -> tuple[int, int]: ...
def pose_verdict(H_target: np.ndarray, H_tool: np.ndarray, q: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                 axis: int) -> tuple[float, float, bool]: ...
def usual_inputs(H: np.ndarray, q0: np.ndarray, n: int, lower: np.ndarray, upper: np.ndarray, anchor: np.ndarray,
                 radius: float, pstar: np.ndarray, Rstar: np.ndarray) -> int: ...
