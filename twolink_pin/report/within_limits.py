"""The report's section "The reference within the limits": the report's reference, its
time-optimal retiming and the minimum-effort trajectory through the same via points side by
side, and the report's laws tracking each.

**The references.** ``reference``: what the report's runs track (on the twolink the course's
polynomial), as it is; ``time_optimal``: its path timed as fast as the velocity, acceleration
and effort limits allow (:func:`~twolink_pin.trajectory.retiming.time_optimal`, TOPP-RA);
``minimum_effort``: the least ``∫ τᵀτ dt`` through its via points at its via times, within
every limit (:func:`~twolink_pin.trajectory.optimal.optimize`). All on the robot's model (its
payload included), no friction, the whole limits (``limit_scale`` 1). A reference the robot
cannot have (no velocity limit to retime against, a solver that fails) is a note instead of a
row; the others are kept.

**Each reference's row** uses the one definition of each number: its duration is its period
[s]; peak ``|q̇|``, ``|q̈|`` (where a limit is given) and ``|τ|`` as a fraction of the limit per
joint are :func:`~twolink_pin.limits.check_limits`'s peak over its limit (one period on the
check grid, torque by RNEA); ``∫ τᵀτ dt`` [N²·m²·s] is
:func:`~twolink_pin.trajectory.optimal.effort_integral`'s. Each is written to
``references/<key>.json``, a trajectory file every ``--trajectory`` reads (``simulate``,
``compare``, ``animate``; the report's own ``--trajectory`` wants via points).

**The tracking rows**: every row of the report (law or variant), and ``mpc`` (the law that plans
within the limits, :data:`PLANNER`) when the report does not run it, on every reference, with
the report's simulation settings (step, initial offset, plant) for :data:`SETTLE` (at most one
period) and then one period of that reference, its metrics (:func:`~twolink_pin.metrics.compute_metrics`: RMS and max of
``e``, ``ė``, ``τ``, the max ``|e|`` over the last period of the run — its max ``|e|`` over the
whole run is the initial offset's transient: 0.1 rad for every law — and the crossings of the position,
velocity and effort limits). A run that diverges or cannot plan is a row saying so.

**The numbers are the one check grid's** (:func:`~twolink_pin.limits.check_limits`: a sampled
reference on each interval between its samples, where its acceleration jumps and its peaks
are), the grid ``trajectory --time-optimal`` and ``trajectory --trajectory FILE`` of the saved
file print theirs on: the same digits everywhere.

:func:`limits_section` is one worker task (picklable arguments only): the design, the files,
the figures and the runs; it returns the section as ``results.json`` holds it under
``within_limits``.
"""

from __future__ import annotations

import time
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import (
    ControllerError,
    InvalidParameterError,
    OptimizationError,
    SimulationDivergedError,
)
from twolink_pin.law_variant import Variant
from twolink_pin.limits import ACCELERATION, EFFORT, VELOCITY, LimitsCheck, check_limits, joint_limits
from twolink_pin.metrics import compute_metrics
from twolink_pin.report.options import ReportOptions
from twolink_pin.report.runs import reference_trajectory
from twolink_pin.simulation import SimulationResult, simulate
from twolink_pin.trajectory import Trajectory

REFERENCES = {
    "reference": ("the report's reference", "reference"),
    "time_optimal": ("its time-optimal retiming", "time-optimal"),
    "minimum_effort": ("the minimum-effort trajectory", "minimum effort"),
}
"""The references' keys (file names under ``references/``), titles and short names (the
tracking table's), in table order."""
RATIO_KINDS = (VELOCITY, ACCELERATION, EFFORT)
"""The limits whose peak ratio a reference's row gives (a kind no joint limits is left out)."""
FIGURE_PREFIX = "limits_references_"
"""The section's figures: ``figures/limits_references_<velocity|acceleration|torque>.png``."""
CROSSED_KINDS = ("position", "velocity", "effort")
"""The limits whose crossings a tracking row lists."""
SETTLE = 1.0
"""A tracking row runs one period of its reference after ``min(SETTLE, period)`` seconds [s]
for the initial offset to settle: its last period's error is the tracking's (the report's
laws settle the 0.1-rad offset in well under a second on the twolink)."""
PLANNER = "mpc"
"""The law that plans within the limits, tracked on every reference beside the report's."""

__all__ = [
    "FIGURE_PREFIX",
    "PLANNER",
    "REFERENCES",
    "SETTLE",
    "fill_report_runs",
    "limits_section",
    "reference_row",
    "report_run_row",
    "reuses_report_runs",
]


def _design(robot: Any, reference: Any) -> tuple[dict[str, Any], list[str]]:
    """The three references (those the robot can have) and a note for each it cannot."""
    from twolink_pin.trajectory.optimal import optimize
    from twolink_pin.trajectory.retiming import time_optimal

    designed: dict[str, Any] = {"reference": reference}  # a via-point reference, then two sampled
    notes = []
    try:
        designed["time_optimal"] = time_optimal(robot, reference).trajectory
    except (InvalidParameterError, OptimizationError) as exc:
        notes.append(f"no time-optimal retiming: {exc}")
    try:
        designed["minimum_effort"] = optimize(robot, reference, "effort").trajectory
    except (InvalidParameterError, OptimizationError) as exc:
        notes.append(f"no minimum-effort trajectory: {exc}")
    return designed, notes


def _titles(key: str, trajectory: Any) -> tuple[str, str]:
    """The reference's title and short name: :data:`REFERENCES`', the report's a polynomial's
    when it is one."""
    from twolink_pin.trajectory.polynomial import JointTrajectory

    if key == "reference" and isinstance(trajectory, JointTrajectory):
        return "the polynomial through the via points", "polynomial"
    return REFERENCES[key]


def reference_row(robot: Any, trajectory: Trajectory) -> tuple[dict[str, Any], LimitsCheck]:
    """One reference's numbers (module docstring): ``duration_s`` [s], ``peak_ratio`` (kind →
    per-joint peak / limit, None for a joint without that limit; only kinds some joint
    limits), ``effort_integral`` [N²·m²·s], ``within_limits``; and the check they come from."""
    from twolink_pin.trajectory.optimal import effort_integral

    check = check_limits(robot, trajectory)
    ratios = {}
    for kind in RATIO_KINDS:
        if not check.limits.given(kind).any():
            continue
        k = check.of(kind.name)
        ratios[kind.name] = [
            float(p / lim) if np.isfinite(lim) else None for p, lim in zip(k.peak, k.limit, strict=True)
        ]
    row = {
        "duration_s": float(trajectory.period),
        "peak_ratio": ratios,
        "effort_integral": effort_integral(robot, trajectory),
        "within_limits": check.within_limits,
    }
    return row, check


def _tracking_duration(options: ReportOptions, trajectory: Trajectory) -> float:
    """A tracking row's simulated time [s]: :data:`SETTLE` (at most a period) and a period."""
    cfg = options.run.simulation
    period = float(trajectory.period)
    return max(period + min(SETTLE, period), cfg.control_period or 0.0, cfg.dt)


def reuses_report_runs(options: ReportOptions, reference: Trajectory) -> bool:
    """Whether each tracking row on the report's own reference is the first seconds of the
    report's run of that law, which the report then reads instead of running it again
    (:func:`report_run_row`): fixed-step RK4 without sensor noise (each sample is then made
    from the ones before only, and the first samples of a longer run are the shorter run's,
    bit for bit) and runs at least as long as the row's."""
    cfg = options.run.simulation
    return (
        cfg.method == "rk4"
        and options.run.plant.sensor_noise is None
        and _tracking_duration(options, reference) <= cfg.duration
    )


def _track(robot: Any, variant: Variant, options: ReportOptions, trajectory: Trajectory) -> dict[str, Any]:
    """One law on one reference, :data:`SETTLE` and a period (module docstring): its metrics
    and crossings, or what stopped it."""
    duration = _tracking_duration(options, trajectory)
    start = time.perf_counter()
    try:
        controller, plant = options.run.for_law(variant).build(robot)
        result = simulate(controller, plant, trajectory, replace(options.run.simulation, duration=duration))
    except (SimulationDivergedError, ControllerError, OptimizationError, InvalidParameterError) as exc:
        return {"finished": False, "failed": str(exc), "duration_s": duration}
    return _row(result, duration, start)


def _row(result: SimulationResult, duration: float, start: float) -> dict[str, Any]:
    """A finished tracking row of ``result`` (run for ``duration`` [s]; made since ``start``,
    a ``perf_counter`` reading)."""
    metrics = compute_metrics(result)
    return {
        "finished": True,
        "duration_s": duration,
        "metrics": metrics.as_dict(),
        "peak_command": np.asarray(metrics.peak_command).tolist(),
        "crossings": metrics.crossings.summary(),
        "crossed": metrics.crossings.sentences(result.joint_limits, CROSSED_KINDS),
        "seconds": time.perf_counter() - start,
    }


def report_run_row(options: ReportOptions, reference: Trajectory, result: SimulationResult) -> dict[str, Any]:
    """The tracking row on the report's ``reference`` read from the report's run ``result`` of
    the law (when :func:`reuses_report_runs`): its first samples, as long as the row's run.
    Its ``seconds`` are the reading's."""
    start = time.perf_counter()
    duration = _tracking_duration(options, reference)
    samples = replace(options.run.simulation, duration=duration).steps + 1
    size = result.t.shape
    per_sample: dict[str, Any] = {  # every array recorded per sample (one row per time): its first rows
        f.name: value[:samples]
        for f in fields(result)
        if isinstance(value := getattr(result, f.name), np.ndarray) and value.shape[:1] == size
    }
    return _row(replace(result, **per_sample), duration, start) | {"from_report_run": True}


def limits_section(
    rows: list[tuple[str, Variant]], options: ReportOptions, stage: str, reused: bool = False
) -> dict[str, Any]:
    """Worker: the section (module docstring) for the report's ``rows`` (name, variant), its
    reference files under ``stage/references`` and figures under ``stage/figures``; returns
    what ``results.json`` holds under ``within_limits``. With ``reused`` (:func:`reuses_report_runs`)
    the rows' tracking rows on the report's reference are left to :func:`fill_report_runs`
    (``{"law", "reference", "pending": True}``)."""
    from twolink_pin.limits import reference_motion
    from twolink_pin.plotting.within_limits import save_references_figures
    from twolink_pin.trajectory.file import write_trajectory_file

    start = time.perf_counter()
    robot = options.load_robot()
    designed, notes = _design(robot, reference_trajectory(robot, options))
    folder = Path(stage) / "references"
    folder.mkdir(exist_ok=True)
    references, motions = {}, {}
    for key, trajectory in designed.items():
        row, _ = reference_row(robot, trajectory)
        row["title"], row["short"] = _titles(key, trajectory)
        row["file"] = f"references/{key}.json"
        write_trajectory_file(folder / f"{key}.json", trajectory)
        references[key] = row
        label = f"{row['title']}, {row['duration_s']:.4g} s"
        motions[label] = reference_motion(robot, trajectory, 2001)
    figures = save_references_figures(
        motions, joint_limits(robot), Path(stage) / "figures", FIGURE_PREFIX, f"{robot.name}: the references"
    )
    laws = list(rows)
    if PLANNER not in {name for name, _ in rows}:
        from twolink_pin.law_variant import parse_variants

        laws.append((PLANNER, parse_variants((PLANNER,))[0]))
    own = {name for name, _ in rows} if reused else set()
    tracking = [
        {"law": name, "reference": key}
        | (
            {"pending": True}
            if key == "reference" and name in own
            else _track(robot, variant, options, trajectory)
        )
        for key, trajectory in designed.items()
        for name, variant in laws
    ]
    return {
        "references": references,
        "notes": notes,
        "figures": [p.name for p in figures],
        "tracking": tracking,
        "seconds": time.perf_counter() - start,
    }


def fill_report_runs(
    section: dict[str, Any],
    rows: list[tuple[str, Variant]],
    options: ReportOptions,
    robot: Any,
    runs: dict[str, SimulationResult],
) -> dict[str, Any]:
    """``section`` (from :func:`limits_section` with ``reused``) with each pending tracking row
    read from the report's run of its law in ``runs`` (:func:`report_run_row`), or run here
    when that run did not finish."""
    reference = reference_trajectory(robot, options)
    variants = dict(rows)
    tracking = []
    for row in section["tracking"]:
        if row.pop("pending", False):
            name = row["law"]
            if name in runs:
                row |= report_run_row(options, reference, runs[name])
            else:
                row |= _track(robot, variants[name], options, reference)
        tracking.append(row)
    return section | {"tracking": tracking}
