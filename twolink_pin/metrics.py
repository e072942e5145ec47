"""Tracking metrics of a run: the norms behind our Table 2.

The report's Table 2 gives "norms" of errors and torques without saying which. We define
three, each per joint over the whole run ``[0, T]`` with the trapezoidal rule on the
output grid:

* RMS: ``sqrt((1/T) ∫ x² dt)`` — same unit as ``x``;
* L2: ``sqrt(∫ x² dt)`` — unit of ``x`` times √s;
* max: ``max |x|``;

for ``x`` in ``e`` [rad], ``ė`` [rad/s], ``τ`` [N·m] (the torque applied to the arm),
plus ``max |e|`` over the last reference period (the steady-state tracking error).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from twolink_pin.simulation import SimulationResult


class Norms(NamedTuple):
    """One norm of each signal, per joint, shape (nv,) each."""

    e: np.ndarray
    """Of the position error [rad] (L2: [rad·√s])."""
    edot: np.ndarray
    """Of the velocity error [rad/s] (L2: [rad/s·√s])."""
    tau: np.ndarray
    """Of the applied torque [N·m] (L2: [N·m·√s])."""


class Metrics(NamedTuple):
    """Norms of one run (see module docstring)."""

    rms: Norms
    """Root mean square over the run."""
    l2: Norms
    """``sqrt(∫ x² dt)`` over the run."""
    max: Norms
    """``max |x|`` over the run."""
    final_period_max_abs_e: np.ndarray
    """``max |e|`` over the last reference period [rad], shape (nv,)."""

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready nested dict of lists."""
        out: dict[str, Any] = {
            kind: {name: getattr(getattr(self, kind), name).tolist() for name in Norms._fields}
            for kind in ("rms", "l2", "max")
        }
        out["final_period_max_abs_e"] = self.final_period_max_abs_e.tolist()
        return out


def _l2(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.trapezoid(x * x, t, axis=0))


def compute_metrics(result: SimulationResult) -> Metrics:
    """RMS, L2 and max of ``e``, ``ė``, ``τ`` and the last-period max ``|e|`` of ``result``."""
    t = result.t
    signals = {"e": result.e, "edot": result.edot, "tau": result.tau}
    duration = t[-1] - t[0]
    l2 = Norms(**{k: _l2(t, x) for k, x in signals.items()})
    rms = Norms(**{k: x / np.sqrt(duration) for k, x in l2._asdict().items()})
    mx = Norms(**{k: np.abs(x).max(axis=0) for k, x in signals.items()})
    last = t >= t[-1] - result.reference_period - 1e-12
    return Metrics(rms, l2, mx, np.abs(result.e[last]).max(axis=0))
