"""The limits a law relaxed: where and by how much, per run, kind and joint.

A law that keeps the joint limits as the rows of an optimisation (``qp-osc``, ``mpc``) meets
states where they cannot all hold — a push, a start beyond a range, more speed than the
effort can brake. With ``on_infeasible = "relax"`` it then keeps the effort rows hard and
lets the position, velocity and acceleration rows give way, in that order, by as little as
an exact penalty allows (:mod:`twolink_pin.optimal.relaxed`), and goes on. It records each
relaxation here, as the crossings of a run are recorded (:mod:`twolink_pin.limits.crossings`):
per kind and joint the first time [s] and the largest amount, in the kind's unit, and the
number of evaluation instants at which any row was relaxed. The law hands its record out by
run (:meth:`~twolink_pin.controllers.Controller.run_relaxations`); a run's result carries it
(:attr:`~twolink_pin.simulation.SimulationResult.relaxed`) and its summary says so.

What "the amount" is depends on the law's row: ``mpc``'s rows bound the plan's knot states,
so it is how far a knot's planned ``q`` or ``q̇`` was let beyond the limit; ``qp-osc``'s rows
bound ``q̈`` through a damper (``q̇ + h_v q̈ ≤ q̇_max``, ``q + 2h q̇ + h² q̈ ≤ q_max``), so it is
how far the damper's bound was moved, in the limit's unit (``h_v`` or ``h²`` times the row's
slack). Either way it is what the law allowed, not what the arm did: the crossings say that.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

RELAXED_KINDS = ("position", "velocity", "acceleration")
"""The kinds whose rows may be relaxed, in the order they give way (effort never: the motor
cannot exceed it anyway)."""
UNITS = {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s²"}
"""The unit of each kind's amount (a revolute joint's)."""


class RunRelaxation(NamedTuple):
    """One run's relaxations: arrays (k, nv) over :data:`RELAXED_KINDS` × joints."""

    first_time: np.ndarray
    """First time [s] a row of that kind and joint was relaxed; NaN where never."""
    largest: np.ndarray
    """Largest amount it was relaxed by [the kind's unit]; 0 where never."""
    instants: int
    """Evaluation instants (distinct times) at which any row was relaxed."""
    last_time: float
    """The last such time [s] (NaN: never)."""

    @property
    def relaxed(self) -> bool:
        """Whether any row was relaxed."""
        return self.instants > 0

    def events(self) -> list[tuple[str, int, float, float, str]]:
        """``(kind, joint from 0, first time [s], largest amount, unit)`` of every kind and
        joint relaxed, in :data:`RELAXED_KINDS` order."""
        rows = []
        for i, kind in enumerate(RELAXED_KINDS):
            for j in np.flatnonzero(~np.isnan(self.first_time[i])):
                rows.append(
                    (kind, int(j), float(self.first_time[i, j]), float(self.largest[i, j]), UNITS[kind])
                )
        return rows

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``instants``, ``last_time`` and, per kind, ``first_time`` and ``largest``
        per joint (None where never relaxed) with its ``unit``."""
        out: dict[str, Any] = {
            "instants": self.instants,
            "last_time": None if math.isnan(self.last_time) else self.last_time,
        }
        for i, kind in enumerate(RELAXED_KINDS):
            never = np.isnan(self.first_time[i])
            out[kind] = {
                "first_time": [None if n else float(x) for x, n in zip(self.first_time[i], never)],
                "largest": [None if n else float(x) for x, n in zip(self.largest[i], never)],
                "unit": UNITS[kind],
            }
        return out

    def sentences(self, joint_names: tuple[str, ...] | None = None) -> list[str]:
        """One line per kind and joint relaxed: ``velocity limit of joint 4 (panda_joint4)
        relaxed from t = 0.61 s, by up to 0.183 rad/s``."""
        lines = []
        for kind, j, first, largest, unit in self.events():
            name = f" ({joint_names[j]})" if joint_names is not None and j < len(joint_names) else ""
            what = "position range" if kind == "position" else f"{kind} limit"
            lines.append(
                f"{what} of joint {j + 1}{name} relaxed from t = {first:.4g} s, by up to {largest:.3g} {unit}"
            )
        return lines

    def text(self, joint_names: tuple[str, ...] | None = None) -> str:
        """The run's relaxations in one paragraph (empty when none)."""
        if not self.relaxed:
            return ""
        head = (
            f"limits relaxed at {self.instants} evaluation instant(s) up to t = {self.last_time:.4g} s "
            "(the rows could not all hold; the effort limits were kept):"
        )
        return "\n".join([head, *(f"  {line}" for line in self.sentences(joint_names))])


class Relaxations:
    """A law's record of its relaxations, per run of the batch it computes (see the module
    docstring). The law calls :meth:`add` when a row gave way, :meth:`clear` when a new
    simulation starts, and answers :meth:`~twolink_pin.controllers.Controller.run_relaxations`
    with :meth:`of`.

    Args:
        nv: Joints of the law's robot.
    """

    def __init__(self, nv: int) -> None:
        self.nv = int(nv)
        self._runs: dict[int, list[Any]] = {}

    def clear(self) -> None:
        """Forget every run's record (a new simulation)."""
        self._runs.clear()

    def add(self, run: int, t: float, amounts: np.ndarray) -> None:
        """Record that run ``run`` relaxed its rows at time ``t`` [s] by ``amounts``, shape
        (len(RELAXED_KINDS), nv) [each kind's unit; 0 where a row held]."""
        amounts = np.asarray(amounts, dtype=float)
        entry = self._runs.get(run)
        if entry is None:
            k = len(RELAXED_KINDS)
            entry = self._runs[run] = [np.full((k, self.nv), np.nan), np.zeros((k, self.nv)), 0, math.nan]
        first, largest = entry[0], entry[1]
        new = (amounts > 0) & np.isnan(first)
        first[new] = t
        np.maximum(largest, amounts, out=largest)
        if entry[3] != t:  # a new instant (RK4 evaluates twice at a half step)
            entry[2] += 1
            entry[3] = t

    def of(self, run: int) -> RunRelaxation | None:
        """Run ``run``'s record, or None when it relaxed nothing."""
        entry = self._runs.get(run)
        if entry is None:
            return None
        first, largest = entry[0].copy(), entry[1].copy()
        for x in (first, largest):
            x.setflags(write=False)
        return RunRelaxation(first, largest, int(entry[2]), float(entry[3]))
