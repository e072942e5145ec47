"""Closed-loop simulation: one engine for one run or thousands.

=====================  ======================================================================================
``config.py``          :class:`SimulationConfig`, the divergence limit and step bounds
``terms.py``           the Pinocchio terms a law asks for, for one run or N (``terms_for``)
``rigid_terms.py``     M̂, ĝ, Ĉq̇ + ĝ, M̂⁻¹b and the frame kinematics a law asks for
``forward.py``         the plant's accelerations (ABA) for one run or N
``engine.py``          :func:`integrate`: RK4, per-stage or sampled law, N runs, blocks, plant events
``rk4.py``             the engine's RK4 step: the law at every stage, or the plant under a held torque
``samples.py``         what the engine writes: :class:`Samples` (blocks of N runs), the buffers, observers
``divergence.py``      which runs diverged in a block, when, and what was seen (non-finite or too large)
``events.py``          what a plant that pushes back does to a step: wrench, payload step, noise, delay, contact
``sensing.py``         the law's force sensor and force reference (``LawInput.contact``) on a plant with a scene
``task_reference.py``  the desired pose, twist and acceleration a task-space law sees (``law_input``)
``preview.py``         the reference ahead of now a law asks for (its ``preview_times``), sampled per block
``adaptive_step.py``   DOP853 with error control, one run
``containment.py``     a law's one door: read-only inputs, sys.exit / MemoryError named, its output checked
``deadline.py``        the wall-clock bound per simulation (``--timeout``): SIGALRM, an error naming the law
``result.py``          :class:`SimulationResult`
``step_check.py``      the step checked before a run: the start's fastest mode against the integrator's bound
``run.py``             :func:`simulate` (N = 1, recorded)
``storage.py``         results as ``.npz``
=====================  ======================================================================================

N runs with streamed metrics (the batch) and studies over them are in
:mod:`twolink_pin.studies`.
"""

from twolink_pin.simulation.config import DIVERGENCE_LIMIT, MAX_STEPS, SimulationConfig
from twolink_pin.simulation.engine import EngineRun, integrate
from twolink_pin.simulation.result import SimulationResult
from twolink_pin.simulation.run import estimated_truth, simulate
from twolink_pin.simulation.samples import Samples
from twolink_pin.simulation.task_reference import law_input
from twolink_pin.simulation.terms import BatchUnavailableError, default_threads, terms_for

__all__ = [
    "DIVERGENCE_LIMIT",
    "MAX_STEPS",
    "BatchUnavailableError",
    "EngineRun",
    "Samples",
    "SimulationConfig",
    "SimulationResult",
    "default_threads",
    "estimated_truth",
    "integrate",
    "law_input",
    "simulate",
    "terms_for",
]
