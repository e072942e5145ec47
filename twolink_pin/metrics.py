"""Tracking metrics of runs: the norms behind our Table 2, accumulated block by block.

The report's Table 2 gives "norms" of errors and torques without saying which. We define
three, each per joint over the whole run ``[0, T]`` with the trapezoidal rule on the
uniform output grid (spacing ``dt``):

* RMS: ``sqrt((1/T) ∫ x² dt)`` — same unit as ``x``;
* L2: ``sqrt(∫ x² dt) = sqrt(dt (Σ x_k² − ½ (x_0² + x_K²)))`` — unit of ``x`` times √s;
* max: ``max |x|``;

for ``x`` in ``e`` [rad], ``ė`` [rad/s], ``τ`` [N·m] (the torque applied to the arm),
plus ``max |e|`` over the last reference period (the steady-state tracking error), the peak
commanded torque, and the run's crossings of its position, velocity and effort limits (joint,
first time, largest excess: :mod:`twolink_pin.limits.crossings`, the one definition; the
effort's is the commanded torque's, whose first time is ``first_exceeded_at``).

One definition, :class:`Metrics` (batch first; a single run is its N = 1 row), and one
implementation: :class:`RunningMetrics` takes samples block by block (the engine hands it
each block of N runs, so a batch's memory stays O(N)); :func:`compute_metrics` feeds it a
recorded run in one block.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from twolink_pin.arrays import readonly_masked
from twolink_pin.errors import InvalidParameterError, require_type
from twolink_pin.limits.crossings import Crossings, RunningCrossings
from twolink_pin.limits.joint_limits import JointLimits

if TYPE_CHECKING:
    from twolink_pin.simulation import Samples, SimulationResult


SIGNALS = (("e", "e", "rad"), ("edot", "ė", "rad/s"), ("tau", "τ", "N·m"))
"""``(field of Norms, symbol, SI unit)`` of each signal: the one list every table reads."""
NORMS = {"rms": ("RMS = sqrt((1/T)∫x² dt)", ""), "l2": ("L2 = sqrt(∫x² dt)", "·√s"), "max": ("max |x|", "")}
"""Title and unit suffix of each norm (a field of :class:`Metrics`)."""
RUN_METRICS = {"final_period_max_abs_e": "rad", "peak_command": "N·m"}
"""Per-joint metrics beyond the norms, and their SI units (fields of :class:`Metrics`)."""
TABLE_NORMS = ("rms", "max")
"""The norms a one-row-per-run table (the sweep's) carries (L2 is RMS·√T there)."""


def metric_units(norms: tuple[str, ...] = TABLE_NORMS) -> dict[str, str]:
    """``{"rms_e": "rad", ..., "peak_command": "N·m"}``: every per-joint metric of a run's row,
    in column order, with its SI unit (a column name adds the joint's 1-based index)."""
    units = {f"{kind}_{field}": unit + NORMS[kind][1] for kind in norms for field, _, unit in SIGNALS}
    return units | RUN_METRICS


def metric_array(metrics: Metrics, stem: str) -> np.ndarray:
    """The array of metric ``stem`` (a key of :func:`metric_units`), shape (N, nv)."""
    kind, _, field = stem.partition("_")
    if kind in NORMS and field in Norms._fields:
        return np.asarray(getattr(getattr(metrics, kind), field))
    return np.asarray(getattr(metrics, stem))


class Norms(NamedTuple):
    """One norm of each signal, per joint: shape (nv,) for a run, (N, nv) for a batch."""

    e: np.ndarray
    """Of the position error [rad] (L2: [rad·√s])."""
    edot: np.ndarray
    """Of the velocity error [rad/s] (L2: [rad/s·√s])."""
    tau: np.ndarray
    """Of the applied torque [N·m] (L2: [N·m·√s])."""


class Metrics(NamedTuple):
    """The metrics of N runs (see the module docstring), batch first: arrays of shape
    (N, nv), rows of diverged runs NaN. One run's (:func:`compute_metrics`, :meth:`run`) is
    the same class with the run axis taken away: arrays of shape (nv,).

    The one definition behind the summary line, the comparison table, the sweep's columns
    (:func:`metric_array`) and the report.
    """

    rms: Norms
    """Root mean square of ``e`` [rad], ``ė`` [rad/s], applied ``τ`` [N·m] over the run."""
    l2: Norms
    """``sqrt(∫ x² dt)`` of the same signals over the run."""
    max: Norms
    """``max |x|`` of the same signals over the run."""
    final_period_max_abs_e: np.ndarray
    """``max |e|`` over the last reference period [rad]."""
    peak_command: np.ndarray
    """``max |τ_command|`` [N·m] (before saturation)."""
    crossings: Crossings
    """Where the motion went past its position, velocity and effort limits (first time [s],
    largest excess), :mod:`twolink_pin.limits.crossings`."""

    @property
    def first_exceeded_at(self) -> np.ndarray:
        """First time [s] ``|τ_command|`` exceeded the joint's limit; NaN if never (the
        effort's crossings)."""
        return self.crossings.effort.first_time

    def run(self, i: int) -> Metrics:
        """Run ``i``'s metrics: arrays of shape (nv,)."""

        def pick(n: Norms) -> Norms:
            return Norms(n.e[i], n.edot[i], n.tau[i])

        return Metrics(
            pick(self.rms),
            pick(self.l2),
            pick(self.max),
            self.final_period_max_abs_e[i],
            self.peak_command[i],
            self.crossings.run(i),
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready nested dict of lists: the norms and ``final_period_max_abs_e``."""
        out: dict[str, Any] = {
            kind: {name: np.asarray(getattr(getattr(self, kind), name)).tolist() for name in Norms._fields}
            for kind in ("rms", "l2", "max")
        }
        out["final_period_max_abs_e"] = np.asarray(self.final_period_max_abs_e).tolist()
        return out


BatchMetrics = Metrics
"""The former name of :class:`Metrics` of N runs (the same class)."""


_SIGNALS = Norms._fields


class RunningMetrics:
    """Running sums and maxima of N runs' signals, fed block by block (an engine observer).

    Args:
        runs: N.
        nv: Joints.
        dt: Output grid spacing [s].
        samples: Total number of samples K (sample K − 1 ends the run).
        period: Reference period [s] (the "last period" window).
        limits: The joint limits the crossings are counted against
            (:attr:`~twolink_pin.plant.Plant.joint_limits`), or the effort limits alone [N·m],
            shape (nv,).
        applied: Maps commanded to applied torque (the plant's saturation).
    """

    def __init__(
        self,
        runs: int,
        nv: int,
        dt: float,
        samples: int,
        period: float,
        limits: JointLimits | np.ndarray,
        applied: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.dt, self.samples = dt, samples
        self.duration = (samples - 1) * dt
        self.last_start = self.duration - period - 1e-12
        if not isinstance(limits, JointLimits):
            none = np.full(nv, np.inf)
            names = tuple(f"joint{j + 1}" for j in range(nv))
            limits = JointLimits(names, -none, none, none, none, np.asarray(limits, dtype=float))
        self.limits = limits.effort
        self.crossings = RunningCrossings(limits, runs)
        self.applied = applied if applied is not None else (lambda tau: tau)
        self.square = {name: np.zeros((runs, nv)) for name in _SIGNALS}
        self.ends = {name: np.zeros((runs, nv)) for name in _SIGNALS}
        self.peak = {name: np.zeros((runs, nv)) for name in _SIGNALS}
        self.final_e = np.zeros((runs, nv))
        self.peak_command = np.zeros((runs, nv))

    def add(self, samples: Samples) -> None:
        """Add a block of samples (arrays (B, N, nv))."""
        e = samples.q - samples.q_des
        signals = {"e": e, "edot": samples.v - samples.v_des, "tau": self.applied(samples.tau_command)}
        stop = samples.start + len(samples.t)
        for name, x in signals.items():
            x2 = x * x
            self.square[name] += x2.sum(axis=0)
            if samples.start == 0:
                self.ends[name] += x2[0]
            if stop == self.samples:
                self.ends[name] += x2[-1]
            np.maximum(self.peak[name], np.abs(x).max(axis=0), out=self.peak[name])
        late = samples.t >= self.last_start
        if late.any():
            np.maximum(self.final_e, np.abs(e[late]).max(axis=0), out=self.final_e)
        np.maximum(self.peak_command, np.abs(samples.tau_command).max(axis=0), out=self.peak_command)
        self.crossings.add(samples.t, samples.q, samples.v, samples.tau_command)

    def result(self, dead: np.ndarray | None = None) -> Metrics:
        """The metrics so far; rows of ``dead`` runs (mask, shape (N,)) are NaN."""
        l2 = Norms(*(np.sqrt(self.dt * (self.square[k] - 0.5 * self.ends[k])) for k in _SIGNALS))
        rms = Norms(*(x / np.sqrt(self.duration) for x in l2))
        mx = Norms(*(self.peak[k] for k in _SIGNALS))

        def clean(x: np.ndarray) -> np.ndarray:
            return readonly_masked(x, dead)

        return Metrics(
            Norms(*(clean(x) for x in rms)),
            Norms(*(clean(x) for x in l2)),
            Norms(*(clean(x) for x in mx)),
            clean(self.final_e),
            clean(self.peak_command),
            self.crossings.result(dead),
        )


def _require_finite(result: SimulationResult) -> None:
    """Refuse a result with a non-finite sample, naming the signal and the first such time [s]."""
    for name in ("q", "v", "tau", "q_des", "v_des"):
        values = np.asarray(getattr(result, name))
        bad = ~np.all(np.isfinite(values), axis=tuple(range(1, values.ndim)))
        if bad.any():
            k = int(np.argmax(bad))
            raise InvalidParameterError(
                "result",
                f"non-finite {name} from t = {float(result.t[k]):.6g} s (sample {k})",
                "finite samples: the metrics of a run holding NaN or inf would be NaN",
            )


def compute_metrics(result: SimulationResult) -> Metrics:
    """RMS, L2 and max of ``e``, ``ė``, ``τ``, the last-period max ``|e|``, the peak command and
    the crossings of ``result`` (against :attr:`~twolink_pin.simulation.SimulationResult.joint_limits`).

    Raises:
        InvalidParameterError: ``result`` is not a :class:`SimulationResult`, or holds a
            non-finite sample (named with its time): its metrics would be NaN.
    """
    from twolink_pin.simulation import Samples, SimulationResult

    require_type(result, SimulationResult, "result", "a SimulationResult (twolink_pin.simulate)")
    _require_finite(result)

    nv = result.q.shape[1]
    column = lambda x: x[:, None, :]  # noqa: E731  # (K, nv) -> (K, 1, nv)
    applied = column(result.tau)  # the torque the plant applied, as recorded
    running = RunningMetrics(
        1, nv, result.dt, len(result.t), result.reference_period, result.joint_limits, lambda _: applied
    )
    zeros = np.zeros((len(result.t), 1, 0))
    running.add(
        Samples(
            0,
            result.t,
            column(result.q),
            column(result.v),
            zeros,
            column(result.tau_command),
            column(result.q_des),
            column(result.v_des),
            column(result.a_des),
        )
    )
    return running.result().run(0)
