"""What is wrong with a log, said before (or beside) the numbers it would give.

:func:`check_log` refuses a log whose units are not the toolkit's, or where a joint never
moves, naming what it saw and what was expected (instead of letting the filter blame its
cut-off, or the sample count blame the length of the run):

* **time in milliseconds** (or microseconds): a median step of :data:`MS_STEP` or more would
  be a sampling rate below 20 Hz; read as ms it is an arm's usual 0.1–10 kHz;
* **angles in degrees**: a joint beyond its URDF limits by more than :data:`LIMIT_SLACK` of
  its range, or a joint without limits beyond ``±2π`` by the same, whose values times
  ``π/180`` are within them;
  otherwise beyond the limits is refused as such;
* **torques in another unit**: a joint's largest ``|τ|`` above :data:`TORQUE_FACTOR` × its
  URDF effort limit (mN·m, or counts);
* **a joint that never moves**: its positions span less than :data:`STILL_RANGE` rad: its
  parameters cannot be identified and every sample would be dropped as sticking.

:func:`fit_warnings` looks at an identification: a condition number above
:data:`CONDITION_WARNING` names the worst-determined parameters (largest ``σ/|θ̂|``) and
suggests ``twolink-pin excite``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from twolink_pin.errors import InputFileError
from twolink_pin.identification.data import RunLog
from twolink_pin.model import RobotModel

MS_STEP = 0.05
"""A median time step of this many seconds or more (below 20 Hz) is suspected to be in ms."""
LIMIT_SLACK = 0.1
"""Positions beyond a joint's limits by more than this fraction of its range are refused."""
TORQUE_FACTOR = 10.0
"""Torques above this multiple of the effort limit are taken for another unit."""
STILL_RANGE = 1e-3
"""A joint whose positions span less than this [rad] never moves."""
CONDITION_WARNING = 100.0
"""Condition number of W above which a warning names the worst-determined parameters: the
relative error of the least-excited combination can then be 100 × that of the torques (the
optimised excitations here reach 2.4 for the twolink, 64 for the UR5)."""


def check_log(log: RunLog, robot: RobotModel) -> None:
    """Refuse ``log`` with the reason if its units or motion are wrong (module docstring).

    Raises:
        InputFileError: time in ms, angles in degrees or beyond the limits, torques in another
            unit, or a joint that never moves (named).
    """
    where = log.source or "log"
    names = [str(n) for n in robot.model.names[1:]]
    step = float(np.median(np.diff(log.t))) if log.samples > 1 else 0.0
    if step >= MS_STEP:
        rate = 1.0 / step
        hint = (
            f"time looks like milliseconds (read as ms: {1e3 * rate:.6g} Hz); give t in seconds"
            if 1e-4 <= step * 1e-3 <= 1e-2
            else "expected an arm's log at 100 Hz or more"
        )
        raise InputFileError(
            where, f"median time step {step:.6g} s is a sampling rate of {rate:.3g} Hz: {hint}"
        )
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for j, name in enumerate(names):
        q = log.q[:, j]
        low, high = (
            (float(lower[j]), float(upper[j]))
            if np.isfinite(lower[j]) and np.isfinite(upper[j])
            else (-2 * math.pi, 2 * math.pi)
        )
        kind = "limits" if np.isfinite(lower[j]) else "±2π (no limits in the URDF)"
        slack = LIMIT_SLACK * (high - low)
        q_min, q_max = float(q.min()), float(q.max())
        if q_min < low - slack or q_max > high + slack:
            degrees = low - slack <= math.radians(q_min) and math.radians(q_max) <= high + slack
            raise InputFileError(
                where,
                f"joint '{name}' (q{j + 1}) spans {q_min:.6g} to {q_max:.6g} rad, beyond its {kind} "
                f"[{low:.4g}, {high:.4g}] rad"
                + (": the angles look like degrees; give q in radians" if degrees else ""),
            )
        if q_max - q_min < STILL_RANGE:
            raise InputFileError(
                where,
                f"joint '{name}' (q{j + 1}) never moves (its positions span {q_max - q_min:.3g} rad): its parameters "
                "cannot be identified; log a run where every joint moves (twolink-pin excite designs one)",
            )
    for j, name in enumerate(names):
        limit = float(robot.torque_limits[j])
        peak = float(np.max(np.abs(log.tau[:, j])))
        if math.isfinite(limit) and limit > 0 and peak > TORQUE_FACTOR * limit:
            raise InputFileError(
                where,
                f"joint '{name}' (tau{j + 1}) reaches {peak:.6g}, {peak / limit:.3g} × its effort limit {limit:g} N·m: "
                "the torques look like another unit (mN·m? motor current?); give them in N·m",
            )


def fit_warnings(result: Any, count: int = 3) -> list[str]:
    """Warnings about an identification: a condition number above :data:`CONDITION_WARNING`
    names the ``count`` parameters with the largest relative standard deviation."""
    if not result.condition_number > CONDITION_WARNING:
        return []
    relative = np.nan_to_num(np.asarray(result.relative_std, dtype=float), nan=np.inf)
    worst = np.argsort(-relative)[:count]
    named = ", ".join(f"{result.names[i]} (σ/|θ| {relative[i]:.3g} %)" for i in worst)
    return [
        f"warning: condition number {result.condition_number:.4g} > {CONDITION_WARNING:g}: the log excites some "
        f"parameters poorly; worst determined: {named}; design an excitation with twolink-pin excite "
        "and log the arm along it"
    ]
