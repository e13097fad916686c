"""FABRIK (Aristidou & Lasenby, 2011) as a benchmark reference: the yardstick the FRDM paper names.

Position only, compiled like kinelab's own kernels (:mod:`kinelab.core._fabrik`) so that a comparison is of
methods, not of languages. The chain's key points are the joint origins and the tool point (docs/methods.md §1.2's
vector model). One iteration is the paper's two passes:

- forward reaching: the tool point is put on the target and each key point, from the tip back, on the
  way towards its previous position at its fixed distance from the next, keeping its offset along the
  joint axis the next point turns about (the original places it on the straight line; with the offset
  the arms with shoulder and wrist offsets need two to four times fewer iterations);
- backward reaching, from the fixed base, with the joint constraints applied joint by joint as the
  paper's §5 does: joint k turns about its own axis (a hinge, not the original's ball joint), or slides
  along it, to bring the key points downstream of it nearest, in least squares, to where the forward
  pass put them, and is then clipped into its limits.

Iterations stop when the tool point is within the tolerance, or after ten iterations that gain less than
a thousandth of the best error (a stall: the adapter restarts from a seeded random configuration). The
joint limits are honoured, by the clipping; nothing else is (no self-collision, no rotation target).
"""

from __future__ import annotations

import itertools
import time

import numpy as np

from kinelab.core._fabrik import attempt
from kinelab.ik.chain import chain_model
from kinelab.report.bench.protocol import TOL_POS, Case, SolveFn
from kinelab.robot import Chain

MAX_ITERATIONS = 500  # per attempt; a converging run needs tens to a few hundred, a stall ends it sooner


def prepare(robot: Chain, budget: float, max_attempts: int | None = None) -> SolveFn:
    """The bench adapter: FABRIK attempts from the case's start, then from seeded random starts, until one
    reaches the target point within TOL_POS, the budget [s] is spent or ``max_attempts`` have run (None: no
    count; a test bounds the attempts, not the time, so that its verdict does not depend on the machine's load)."""
    model = chain_model(robot)
    ch, lower, upper = model.chain, model.lower, model.upper

    def run(case: Case, seed: int) -> tuple:
        t_end = time.perf_counter() + budget
        rng = np.random.default_rng(seed)
        q, target, total = case.q_start.astype(float), np.ascontiguousarray(case.oMtarget.translation), 0
        for tries in itertools.count(1):
            iterations, error = attempt(ch, lower, upper, target, q, TOL_POS * 0.5, MAX_ITERATIONS)
            total += iterations
            if error <= TOL_POS * 0.5 or time.perf_counter() > t_end or tries == max_attempts:
                break
            q = robot.random_q(rng)
        return q, total

    return run
