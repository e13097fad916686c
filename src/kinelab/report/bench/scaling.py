"""FRDM cost against chain length: synthetic serial chains of 7 to 100 links, revolute and prismatic mixed.

Time per sweep is measured on the compiled kernel alone (plain sweeps, a fixed count, a target it
cannot reach so that it never stops early); time per solve through :func:`kinelab.solve`. A straight
line is fitted to time per sweep against the number of links and its R² reported.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import pinocchio as pin
from tqdm import tqdm

from kinelab.ik.api import solve
from kinelab.ik.chain import chain_model
from kinelab.ik.frdm import kernel
from kinelab.report.bench import peers
from kinelab.robot import Chain
from kinelab.robot.reduce import build_file
from kinelab.scratch import scratch_dir

LENGTHS = (7, 15, 30, 60, 100)


def synthetic_urdf(n: int, seed: int = 0, link: float | None = None) -> str:
    """A serial chain of ``n`` joints (every fourth prismatic) with random axes and offsets, total length ≈ 2 m."""
    rng = np.random.default_rng(seed)
    link = link or 2.0 / n
    parts = ['<?xml version="1.0"?>', f'<robot name="chain{n}">', '<link name="base"/>']
    for i in range(n):
        parts.append(f'<link name="l{i}"/>')
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        offset = rng.normal(scale=0.3 * link, size=3) + np.array([0, 0, link])
        parent = "base" if i == 0 else f"l{i - 1}"
        kind, lo, hi = ("prismatic", -0.5 * link, 0.5 * link) if i % 4 == 3 else ("revolute", -2.5, 2.5)
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{offset[0]:.6f} {offset[1]:.6f} {offset[2]:.6f}"/>'
            f'<axis xyz="{axis[0]:.6f} {axis[1]:.6f} {axis[2]:.6f}"/>'
            f'<limit lower="{lo:.6f}" upper="{hi:.6f}" effort="1" velocity="1"/></joint>'
        )
    parts += ['<link name="tool"/>', f'<joint name="jt" type="fixed"><parent link="l{n - 1}"/><child link="tool"/>'
              f'<origin xyz="0 0 {link:.6f}"/></joint>', "</robot>"]
    return "\n".join(parts)


def synthetic_robot(n: int, seed: int = 0) -> Chain:
    """A synthetic n-link chain (every fourth joint prismatic), loaded from a temporary URDF."""
    path = scratch_dir("kinelab-chain-") / f"chain{n}.urdf"
    path.write_text(synthetic_urdf(n, seed))
    return Chain(build_file(path, name=f"chain{n}"))


def time_per_sweep(robot: Chain, sweeps: int = 500, repeats: int = 30) -> float:
    """Seconds per plain FRDM sweep (kernel only, FK resync included), best of ``repeats`` (the minimum
    is what the code costs; a shared machine only ever adds to it)."""
    cm = chain_model(robot)
    far = pin.SE3(np.eye(3), np.array([100.0, 0.0, 0.0]))  # unreachable: the kernel never stops early
    problem = kernel.Objective(cm.lower, cm.upper, np.ones(cm.n, dtype=np.bool_), far.translation.copy(),
                             far.rotation.copy(), 1.0 / cm.length**2, np.ones(3), 1e-300, 1e-300, True, True,
                             np.zeros(cm.n), 0.0, -1)
    settings = kernel.Settings(1.0, -1.0, sweeps + 1, -1.0, 0, 0, 0.0, 0)  # the sweeps alone: no finish
    best = np.inf
    for _ in range(repeats + 1):
        q = robot.neutral()
        mem = kernel.new_memory(cm.n, 0)
        mem.state[kernel.S_E_WINDOW] = np.inf
        t0 = time.perf_counter()
        kernel.run(q, cm.chain, problem, settings, kernel.BASE_TO_TIP, sweeps, mem)
        best = min(best, (time.perf_counter() - t0) / sweeps)
    return best


def time_per_solve(robot: Chain, count: int = 20, seed: int = 0, solver: str = "frdm") -> tuple[float, float]:
    """(median seconds per solve, success rate) of :func:`kinelab.solve` on reachable random targets (0.5 s
    budget each), or of roboticstoolbox's ``ik_LM`` on an ETS built from the same chain (``solver="ik_LM"``),
    every answer judged by Pinocchio."""
    rng = np.random.default_rng(seed)
    problems = [(robot.fk(robot.random_q(rng)), robot.random_q(rng)) for _ in range(count)]
    run = _ik_lm(robot) if solver == "ik_LM" else None
    times, ok = [], 0
    for k, (target, q0) in enumerate(problems):
        t0 = time.perf_counter()
        q = run(target, q0) if run is not None else solve(robot, target, solver=solver, q0=q0, seed=k,
                                                            time_budget=0.5).q
        times.append(time.perf_counter() - t0)
        dp, dr = robot.tool_error(q, target)
        ok += dp <= 1e-6 and dr <= 1e-6 and robot.within_limits(q)
    return float(np.median(times)), ok / count


def _ik_lm(robot: Chain) -> Callable[[pin.SE3, np.ndarray], np.ndarray]:
    ets = peers.rtb_chain_ets(robot)

    def run(target: pin.SE3, q0: np.ndarray) -> np.ndarray:
        return np.asarray(ets.ik_LM(target.homogeneous, q0=q0, tol=5e-13, joint_limits=True).q, dtype=float)

    return run


def linear_fit(x, y) -> tuple[float, float, float]:
    """(intercept, slope, R²) of the least-squares line y = a + b x."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    b, a = np.polyfit(x, y, 1)
    residual = y - (a + b * x)
    r2 = 1.0 - residual @ residual / ((y - y.mean()) @ (y - y.mean()))
    return float(a), float(b), float(r2)


def run(lengths: tuple[int, ...] = LENGTHS, seed: int = 0, progress: bool = False, solves: int = 20) -> dict:
    """FRDM's time per sweep and full solves (FRDM, DLS, ik_LM) on synthetic chains of each length."""
    rows = []
    for n in tqdm(lengths, desc="scaling", disable=not progress, unit="chain"):
        robot = synthetic_robot(n, seed)
        sweep_s = time_per_sweep(robot)
        row = {"links": n, "us_per_sweep": sweep_s * 1e6}
        for solver in ("frdm", "dls", "ik_LM") if solves else ():
            try:
                solve_s, rate = time_per_solve(robot, solves, seed, solver)
            except ImportError:  # roboticstoolbox not installed
                continue
            row[f"{solver}_us_per_solve"], row[f"{solver}_solved"] = solve_s * 1e6, rate
        rows.append(row)
    a, b, r2 = linear_fit([r["links"] for r in rows], [r["us_per_sweep"] for r in rows])
    return {"rows": rows, "fit_us_per_sweep": {"intercept": a, "slope_per_link": b, "r2": r2}}


def markdown(result: dict) -> str:
    """The scaling result as Markdown tables."""
    fit = result["fit_us_per_sweep"]
    lines = ["| links | FRDM µs per sweep | FRDM µs per solve | solved | DLS µs per solve | solved | "
             "ik_LM µs per solve | solved |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        cells = [f"{r['us_per_sweep']:.2f}"]
        for solver in ("frdm", "dls", "ik_LM"):
            if f"{solver}_us_per_solve" in r:
                cells += [f"{r[f'{solver}_us_per_solve']:.0f}", f"{100 * r[f'{solver}_solved']:.0f} %"]
            else:
                cells += ["–", "–"]
        lines.append(f"| {r['links']} | " + " | ".join(cells) + " |")
    lines.append(f"\nTime per sweep ≈ {fit['intercept']:.2f} + {fit['slope_per_link']:.3f} µs × links, "
                 f"R² = {fit['r2']:.4f}.")
    return "\n".join(lines)
