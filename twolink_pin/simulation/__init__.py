"""Closed-loop simulation: one engine for one run or thousands.

======================  ==================================================================

N runs with streamed metrics (the batch) and studies over them are in
:mod:`twolink_pin.studies`.
"""

from twolink_pin.simulation.config import DIVERGENCE_LIMIT, MAX_STEPS, SimulationConfig
from twolink_pin.simulation.engine import EngineRun, Samples, integrate
from twolink_pin.simulation.result import SimulationResult
from twolink_pin.simulation.run import estimated_truth, simulate
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
