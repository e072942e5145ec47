"""The engine's classical RK4 step on ``(N, nv)`` state rows, and the factors it multiplies by.

* :func:`stage_step`: one step with the law evaluated at every stage (its first output given);
  the reference rows of the step's half-step grid, the clock set to each stage's time (error
  messages, ``--timeout``).
* :func:`held_step`: one step of the plant under a held torque (a sampled or delayed law), the
  law's state advanced by Euler; :func:`held_rk4` binds it to a plant's accelerations (a plant
  whose own integrator steps it brings its own ``held_step``).

Every product is on numpy's fast path at any N: the factors are 0-d arrays (:class:`Steps`),
never Python floats or (1, width) rows. The arithmetic is the textbook's, in a fixed order:
a batch of N runs and N single runs give the same bits.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers import LawInput


class Clock:
    """The simulated time of the law evaluation under way [s] (error messages, ``--timeout``)."""

    now = 0.0


class Steps(NamedTuple):
    """The step's factors as read-only 0-d arrays: numpy multiplies a 0-d array into an (N, w)
    one on its fast path at any N — a Python float costs 1.6 times as much at N = 1, a (1, w)
    row 8 to 11 times as much at N = 1000 (an inner loop of w per run) — with the same products."""

    dt: float
    """The step [s]."""
    h: np.ndarray
    """``dt`` [s]."""
    h2: np.ndarray
    """``dt / 2`` [s]."""
    h6: np.ndarray
    """``dt / 6`` [s]."""
    two: np.ndarray
    """2 (the weight of the middle stages)."""

    @classmethod
    def of(cls, dt: float) -> Steps:
        """The factors of a step of ``dt`` [s]."""
        factors = [np.array(x) for x in (dt, dt / 2, dt / 6, 2.0)]
        for x in factors:
            x.setflags(write=False)
        return cls(dt, *factors)


def stage_step(
    compute: Callable[[Any, Any], Any],
    terms: Any,
    accel: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    tau1: np.ndarray,
    dz1: np.ndarray,
    ref: Any,
    i: int,
    t: float,
    steps: Steps,
    nz: int,
    clock: Clock,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One classical RK4 step from ``(q, v, z)`` at ``t`` with the law at every stage (its first
    output ``tau1``, ``dz1`` given; ``ref[i]``: the reference rows of half-step i)."""
    new = tuple.__new__  # LawInput(...) through tuple.__new__: twice as cheap as its __new__
    dt, h, h2, h6, two = steps
    a1 = accel(q, v, tau1)
    clock.now = now = t + dt / 2
    q2, v2 = q + h2 * v, v + h2 * a1
    z2 = z + h2 * dz1 if nz else z
    tau2, dz2 = compute(new(LawInput, (now, q2, v2, z2, *ref[i + 1])), terms)
    a2 = accel(q2, v2, tau2)
    q3, v3 = q + h2 * v2, v + h2 * a2
    z3 = z + h2 * dz2 if nz else z
    tau3, dz3 = compute(new(LawInput, (now, q3, v3, z3, *ref[i + 1])), terms)
    a3 = accel(q3, v3, tau3)
    clock.now = now = t + dt
    q4, v4 = q + h * v3, v + h * a3
    z4 = z + h * dz3 if nz else z
    tau4, dz4 = compute(new(LawInput, (now, q4, v4, z4, *ref[i + 2])), terms)
    a4 = accel(q4, v4, tau4)
    if nz:
        z = z + h6 * (dz1 + two * (dz2 + dz3) + dz4)
    return q + h6 * (v + two * (v2 + v3) + v4), v + h6 * (a1 + two * (a2 + a3) + a4), z


def held_rk4(accel: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]) -> Callable[..., Any]:
    """The engine's held step on ``accel`` (a plant that steps itself has its own ``held_step``)."""
    return lambda *state: held_step(accel, *state)


def held_step(
    accel: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    tau: np.ndarray,
    dz: np.ndarray,
    steps: Steps,
    nz: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One RK4 step of the plant under the held torque ``tau``; ``z ← z + dt ż``."""
    _, h, h2, h6, two = steps
    a1 = accel(q, v, tau)
    q2, v2 = q + h2 * v, v + h2 * a1
    a2 = accel(q2, v2, tau)
    q3, v3 = q + h2 * v2, v + h2 * a2
    a3 = accel(q3, v3, tau)
    q4, v4 = q + h * v3, v + h * a3
    a4 = accel(q4, v4, tau)
    if nz:
        z = z + h * dz
    return q + h6 * (v + two * (v2 + v3) + v4), v + h6 * (a1 + two * (a2 + a3) + a4), z


__all__ = ["Clock", "Steps", "held_rk4", "held_step", "stage_step"]
