"""kinelab's own solvers as bench adapters: each becomes prepare(robot, budget) → solve(case, seed)."""

from __future__ import annotations

from typing import Any

from kinelab.ik import solve
from kinelab.report.bench.protocol import TOL_POS, TOL_ROT, Case, Prepare, SolveFn
from kinelab.robot import Chain


def kinelab_solver(solver: str, **options: Any) -> Prepare:
    """A bench adapter for ``kinelab.solve(..., solver=solver, **options)``."""

    def prepare(robot: Chain, budget: float) -> SolveFn:
        def run(case: Case, seed: int) -> tuple:
            res = solve(robot, case.oMtarget, solver=solver, q0=case.q_start, seed=seed, time_budget=budget,
                        tol_pos=TOL_POS, tol_rot=TOL_ROT, task=case.task, **options)
            return res.q, res.iterations

        return run

    return prepare


KINELAB_SOLVERS: dict[str, Prepare] = {
    "frdm": kinelab_solver("frdm"),
    "frdm-plain": kinelab_solver("frdm", accel="none"),
    "biquat": kinelab_solver("biquat"),
    "dls": kinelab_solver("dls"),
}
