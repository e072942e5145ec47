"""The crossings of a run: where the actual motion went past a limit, joint by joint.

A run *crosses* a limit of a joint at the samples where the quantity the limit bounds lies
strictly beyond it (:meth:`~twolink_pin.limits.JointLimits.excess` > 0): the position
``q`` outside its range, ``|q̇|`` above the velocity limit, the commanded ``|τ|`` above the
effort limit (the torque the law asked for, before any saturation: what a motor would have
had to give). Of each crossed joint and kind a run records two numbers:

* ``first_time`` — the first sample time [s] beyond the limit (NaN: never crossed);
* ``excess`` — the largest excess over the limit along the run, in the kind's unit (0: never).

One definition, one implementation: :class:`RunningCrossings` takes samples block by block
(the engine's observers do, so a batch of N runs that is not recorded keeps O(N) memory);
:func:`motion_crossings` feeds it a recorded :class:`~twolink_pin.limits.Motion` in one block.
The metrics of a run (:mod:`twolink_pin.metrics`) carry them; every table and page reads them
from there.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.arrays import readonly_masked
from twolink_pin.limits.joint_limits import JointLimits
from twolink_pin.limits.kinds import EFFORT, POSITION, VELOCITY, LimitKind, Motion

CROSSED_KINDS: tuple[LimitKind, ...] = (POSITION, VELOCITY, EFFORT)
"""The kinds a run's crossings are recorded for: what a run carries at every sample
(``q``, ``q̇``, the commanded ``τ``; the acceleration is not recorded)."""


class KindCrossings(NamedTuple):
    """One kind's crossings: arrays of shape (N, nv) for N runs, (nv,) for one run."""

    kind: LimitKind
    """The kind crossed."""
    first_time: np.ndarray
    """First sample time beyond the limit [s]; NaN where never (and for a diverged run)."""
    excess: np.ndarray
    """Largest excess over the limit [the kind's unit]; 0 where never (NaN: a diverged run)."""

    @property
    def crossed(self) -> np.ndarray:
        """Whether each joint (of each run) crossed its limit."""
        return ~np.isnan(self.first_time)

    def run(self, i: int) -> KindCrossings:
        """Run ``i``'s crossings: arrays of shape (nv,)."""
        return KindCrossings(self.kind, self.first_time[i], self.excess[i])

    def summary(self) -> dict[str, Any]:
        """One run's crossings, JSON-ready: ``crossed`` (per joint), ``first_time`` [s] and
        ``excess`` [the kind's unit] (None where never crossed), ``unit``."""
        crossed = self.crossed.tolist()

        def where_crossed(x: np.ndarray) -> list[float | None]:
            return [float(v) if c and math.isfinite(v) else None for v, c in zip(x.tolist(), crossed)]

        return {
            "crossed": crossed,
            "first_time": where_crossed(self.first_time),
            "excess": where_crossed(self.excess),
            "unit": self.kind.unit,
        }


class Crossings(NamedTuple):
    """A run's (or N runs') crossings of each kind of :data:`CROSSED_KINDS`."""

    position: KindCrossings
    """Outside the position range [rad]."""
    velocity: KindCrossings
    """``|q̇|`` above the velocity limit [rad/s]."""
    effort: KindCrossings
    """Commanded ``|τ|`` above the effort limit [N·m]."""

    def run(self, i: int) -> Crossings:
        """Run ``i``'s crossings."""
        return Crossings(*(k.run(i) for k in self))

    def summary(self) -> dict[str, Any]:
        """One run's crossings, JSON-ready, by kind (:meth:`KindCrossings.summary`)."""
        return {k.kind.name: k.summary() for k in self}

    @property
    def within_limits(self) -> bool:
        """One run's answer for every kind: no joint crossed its position range, velocity or
        effort limit (the ``within_limits`` of a run's JSON)."""
        return not any(bool(k.crossed.any()) for k in self)

    def events(
        self, kinds: tuple[str, ...] = ("position", "velocity")
    ) -> list[tuple[str, int, float, float]]:
        """One run's crossings of ``kinds`` as ``(kind, joint index from 0, first time [s],
        largest excess)``, in kind then joint order."""
        out = []
        for k in self:
            if k.kind.name not in kinds:
                continue
            for j in np.flatnonzero(k.crossed):
                out.append((k.kind.name, int(j), float(k.first_time[j]), float(k.excess[j])))
        return out

    def sentences(self, limits: JointLimits, kinds: tuple[str, ...] = ("position", "velocity")) -> list[str]:
        """One run's crossings of ``kinds`` in words, one per joint and kind: ``joint 2
        (joint2) passed its position range [-3.14, 3.14] rad at t = 1.234 s, by up to 0.05 rad``."""
        out = []
        for kind, j, first, excess in self.events(kinds):
            who = f"joint {j + 1} ({limits.joint_names[j]})"
            if kind == "position":
                what = (
                    f"passed its position range [{limits.position_lower[j]:.4g}, "
                    f"{limits.position_upper[j]:.4g}] rad"
                )
            else:
                k = getattr(self, kind).kind
                bound = float(getattr(limits, kind)[j])
                what = f"exceeded its {bound:.4g} {k.unit} {kind} limit"
            unit = getattr(self, kind).kind.unit
            out.append(f"{who} {what} at t = {first:.4g} s, by up to {excess:.3g} {unit}")
        return out


class RunningCrossings:
    """The crossings of N runs, fed block by block (see the module docstring).

    Args:
        limits: The limits crossed (``±inf``: a joint without one never crosses).
        runs: N.
    """

    def __init__(self, limits: JointLimits, runs: int) -> None:
        self.limits = limits
        nv = limits.nv
        self.first = {k.name: np.full((runs, nv), np.nan) for k in CROSSED_KINDS}
        self.largest = {k.name: np.zeros((runs, nv)) for k in CROSSED_KINDS}
        self.checked = tuple(k for k in CROSSED_KINDS if limits.given(k).any())

    def add(self, t: np.ndarray, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> None:
        """A block of B samples: times ``t`` [s] (B,), positions [rad], velocities [rad/s] and
        commanded torques [N·m], each (B, N, nv)."""
        for kind in self.checked:
            values = (q, v, tau)[CROSSED_KINDS.index(kind)]
            largest = self._largest(kind, values)  # (N, nv)
            crossed = largest > 0
            if not crossed.any():
                continue
            first = self.first[kind.name]
            newly = crossed & np.isnan(first)
            if newly.any():
                over = self.limits.excess(kind, values) > 0  # (B, N, nv)
                first[newly] = t[np.argmax(over, axis=0)][newly]
            np.maximum(self.largest[kind.name], largest, out=self.largest[kind.name])

    def _largest(self, kind: LimitKind, values: np.ndarray) -> np.ndarray:
        """``excess(kind, values).max(axis=0)`` from the block's extremes, the same bits: rounding
        is monotonic, so ``max_s max(v_s − u, l − v_s) = max(max_s v_s − u, l − min_s v_s)``;
        ``fmax``/``fmin`` skip a NaN sample, as ``excess`` makes it ``-inf`` (two reductions of
        the block instead of five passes over it)."""
        lower, upper = self.limits.bounds(kind)
        with np.errstate(invalid="ignore"):
            largest = np.fmax(np.fmax.reduce(values, axis=0) - upper, lower - np.fmin.reduce(values, axis=0))
        return np.where(np.isnan(largest), -np.inf, largest)

    def result(self, dead: np.ndarray | None = None) -> Crossings:
        """The crossings so far; rows of ``dead`` runs (mask, shape (N,)) are NaN."""

        def clean(x: np.ndarray) -> np.ndarray:
            return readonly_masked(x, dead)

        return Crossings(
            *(KindCrossings(k, clean(self.first[k.name]), clean(self.largest[k.name])) for k in CROSSED_KINDS)
        )


def motion_crossings(motion: Motion, limits: JointLimits) -> Crossings:
    """The crossings of one recorded ``motion`` (its ``tau``: the commanded torque; None: no
    effort crossings), arrays of shape (nv,)."""
    column = lambda x: np.asarray(x, dtype=float)[:, None, :]  # noqa: E731  # (K, nv) -> (K, 1, nv)
    tau = motion.tau if motion.tau is not None else np.zeros_like(motion.q)
    running = RunningCrossings(limits if motion.tau is not None else limits_without(limits, EFFORT), 1)
    running.add(np.asarray(motion.t, dtype=float), column(motion.q), column(motion.v), column(tau))
    return running.result().run(0)


def limits_without(limits: JointLimits, kind: LimitKind) -> JointLimits:
    """``limits`` with no ``kind`` limit on any joint (a symmetric kind)."""
    values = {k: getattr(limits, k) for k in ("velocity", "acceleration", "effort")}
    values[kind.name] = np.full(limits.nv, np.inf)
    return JointLimits(limits.joint_names, limits.position_lower, limits.position_upper, **values)


__all__ = [
    "CROSSED_KINDS",
    "Crossings",
    "KindCrossings",
    "RunningCrossings",
    "limits_without",
    "motion_crossings",
]
