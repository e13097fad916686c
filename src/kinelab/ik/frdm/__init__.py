"""FRDM, the finite rotation and displacement method (paper 000).

Reference: Danilov A.V. Test simulation of the finite rotation and displacement method (FRDM) by the
European Robotic Arm passing through singular points. *Bulletin of BSTU named after V.G. Shukhov*
(Vestnik BGTU im. V.G. Shukhova), 2019, no. 11. Method notes: ``docs/methods.md`` §1.

All names below are in :mod:`kinelab.ik` (``chain``) and :mod:`kinelab.ik.frdm`.

| paper section / equation | kinelab |
|---|---|
| vector model: e_i, M_i, tool point N, tool vectors (§1.2) | ``chain.ChainModel.vectors``, ``chain.chain_fk`` |
| exact rotation, E(θ) = a − 2B cos θ − 2C sin θ (§1.3) | ``kernel.revolute_BC``, ``kernel.revolute_angle`` |
| finite displacement of a prismatic joint (§1.4) | ``kernel.sweep`` (prismatic branch) |
| limits, intervals, freezing (§1.5) | ``kernel.revolute_angle`` (window), ``monitor.Runner.apply`` |
| sweep over the chain (§1.6) | ``kernel.sweep``; readable: ``reference.sweep`` |
| monitor Σ|Δq_i| = 0 (§1.6) | ``kernel.run`` (STALL_STEP, STALL_WINDOW), ``monitor.Runner`` |
| bypasses: signed δq, intervals, freezing (§1.7) | ``monitor.Bypass``, ``options.FRDMOptions`` |
| q_i = q_i0 + Σ Δq_ij + Σ δq_ik | the kernel's in-place updates of q |
| direct control along a path (ERA passages) | ``tracking.track``, :mod:`kinelab.studies.paper000_era` |

The readable statement of §1.2–1.4 on Pinocchio's FK is ``reference`` (``vector_model``,
``revolute_step``, ``prismatic_step``); tests hold the kernel to it.

Not in the paper: Anderson acceleration of the sweep map (kept only when it lowers the objective,
:func:`kinelab.ik.frdm.kernel.run`), the position weight w_p = 3/L², seeded restarts.

Modules: ``options`` (FRDMOptions), ``kernel`` (compiled), ``reference`` (readable, on Pinocchio),
``monitor`` (monitor and bypasses), ``solver`` (attempt, multistart), ``tracking`` (paths).
"""

from typing import TYPE_CHECKING

from kinelab.lazy import loader

__getattr__ = loader(__name__, globals(), {"FRDMOptions": ("kinelab.ik.frdm.options", "FRDMOptions")})

if TYPE_CHECKING:
    from kinelab.ik.frdm.options import FRDMOptions

__all__ = ["FRDMOptions"]
