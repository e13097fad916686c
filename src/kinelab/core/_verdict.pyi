import numpy as np

NOT_FINITE: int
NOT_A_ROTATION: int
NOT_HOMOGENEOUS: int

def pose_defect(H: np.ndarray) -> int: ...
def first_defect(H: np.ndarray) -> tuple[int, int]: ...
def pose_verdict(H_target: np.ndarray, H_tool: np.ndarray, q: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                 axis: int) -> tuple[float, float, bool]: ...
