"""Whether an optimised excitation is usable: within its limits, moving, and of bounded cost.

:func:`excitation_problem` says why an :class:`~twolink_pin.identification.excitation.Excitation`
must not be saved as a success — a peak (position, velocity, acceleration, torque) beyond
its limit, or a joint that does not move (its parameters cannot be identified from it);
:func:`excitation_verdict` says what the numbers say of a usable one (feasible, how close
to its nearest limit, whether the optimiser converged or stopped at its iteration limit);
:func:`check_excitation_work` refuses, before any work, a design whose optimisation would run
for days (:data:`MAX_EXCITATION_WORK`).
"""

from __future__ import annotations

import math
from typing import Any

from twolink_pin.errors import InvalidParameterError

MAX_EXCITATION_WORK = 2e8
"""Most starts × iterations × samples × unknowns of one ``excite`` (the default design is
1.3e6 and takes about 30 s of CPU on the twolink; the bound is 150 times that)."""
MOTION_FLOOR = 1e-6
"""Peak speed [rad/s] below which a joint counts as not moving."""
RELATIVE_SLACK = 1e-6
"""Relative excess over a limit tolerated (the optimiser's own feasibility tolerance)."""


def excitation_work(nv: int, harmonics: int, samples: int, starts: int, max_iterations: int) -> float:
    """starts × iterations × samples × unknowns (2 harmonics coefficients per harmonic and
    joint, plus the offset): what the optimisation costs at most, in sample evaluations."""
    return float(starts) * max_iterations * samples * nv * (2 * harmonics + 1)


def check_excitation_work(nv: int, harmonics: int, samples: int, starts: int, max_iterations: int) -> None:
    """Raise if the design's optimisation could exceed :data:`MAX_EXCITATION_WORK`."""
    work = excitation_work(nv, harmonics, samples, starts, max_iterations)
    if work > MAX_EXCITATION_WORK:
        raise InvalidParameterError(
            "--starts × --max-iterations × --samples × unknowns",
            f"{starts} × {max_iterations} × {samples} × {nv * (2 * harmonics + 1)} = {work:.3g}",
            f"at most {MAX_EXCITATION_WORK:.3g} (the default design is "
            f"{excitation_work(nv, 5, 100, 3, 200):.3g}); lower one of them",
        )


PEAKS = (
    ("v_max", "velocity", "speed", "rad/s"),
    ("a_max", "acceleration", "acceleration", "rad/s²"),
    ("tau_max", "torque", "torque", "N·m"),
)
"""(peak key, limit key, name, unit) of the bounded peaks other than position."""


def _over(value: float, bound: float) -> bool:
    return not math.isfinite(value) or (math.isfinite(bound) and value > bound + RELATIVE_SLACK * abs(bound))


def _by(value: float, bound: float, unit: str) -> str:
    """How far ``value`` is beyond ``bound``: absolute and relative to the bound."""
    if not math.isfinite(value):
        return "not a finite number"
    excess = value - bound
    relative = f" ({100.0 * excess / abs(bound):.3g} % of the limit)" if bound != 0 else ""
    return f"over by {excess:.4g} {unit}{relative}"


def excitation_problem(peaks: dict[str, Any], limits: dict[str, Any]) -> str | None:
    """Why the excitation with these ``peaks`` must not be used (None: it may): the first
    limit it exceeds, and by how much."""
    for j, (low, high) in enumerate(zip(peaks["q_min"], peaks["q_max"])):
        lower, upper = limits["lower"][j], limits["upper"][j]
        if _over(-low, -lower) or _over(high, upper):
            side = _by(-low, -lower, "rad") if _over(-low, -lower) else _by(high, upper, "rad")
            return (
                f"joint {j + 1} reaches [{low:.4g}, {high:.4g}] rad, beyond its range "
                f"[{lower:.4g}, {upper:.4g}] rad, {side} (infeasible)"
            )
    for key, limit, name, unit in PEAKS:
        for j, (value, bound) in enumerate(zip(peaks[key], limits[limit])):
            if _over(float(value), float(bound)):
                return (
                    f"peak {name} of joint {j + 1} is {value:.4g} {unit}, beyond its limit {bound:.4g} {unit}, "
                    f"{_by(float(value), float(bound), unit)} (infeasible)"
                )
    still = [j + 1 for j, v in enumerate(peaks["v_max"]) if v < MOTION_FLOOR]
    if still:
        return (
            f"joint{'s' if len(still) > 1 else ''} {', '.join(map(str, still))} do{'' if len(still) > 1 else 'es'} "
            f"not move (peak speed < {MOTION_FLOOR:g} rad/s): nothing can be identified from it"
        )
    return None


def excitation_verdict(peaks: dict[str, Any], limits: dict[str, Any], converged: bool, message: str) -> str:
    """What the numbers say of an excitation: infeasible (:func:`excitation_problem`'s
    reason), or feasible with its closest approach to a limit (percent of the limit used), and
    whether the optimiser converged or stopped (``message``, SLSQP's) before it could."""
    problem = excitation_problem(peaks, limits)
    if problem is not None:
        return problem
    used = []
    for j, (low, high) in enumerate(zip(peaks["q_min"], peaks["q_max"])):
        lower, upper = limits["lower"][j], limits["upper"][j]
        centre, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
        if half > 0:
            used.append(
                (max(high - centre, centre - low) / half, f"position of joint {j + 1}", "of its half range")
            )
    for key, limit, name, _unit in PEAKS:
        for j, (value, bound) in enumerate(zip(peaks[key], limits[limit])):
            if math.isfinite(bound) and bound > 0:
                used.append(
                    (float(value) / float(bound), f"{name} of joint {j + 1}", f"of {bound:.4g} {_unit}")
                )
    fraction, what, of = max(used, key=lambda u: u[0])  # the first of equals
    verdict = f"feasible: every peak within its limit (closest: {what} at {100.0 * fraction:.1f} % {of})"
    if converged:
        return verdict + "; SLSQP converged"
    return (
        verdict + f"; SLSQP stopped before converging ({message}): more --max-iterations or --starts may "
        "lower cond(W)"
    )


__all__ = [
    "MAX_EXCITATION_WORK",
    "check_excitation_work",
    "excitation_problem",
    "excitation_verdict",
    "excitation_work",
]
