"""The report's section "Sim-to-sim": each law of the report on the Pinocchio plant and on MuJoCo
with the arm's effects on, and the difference attributed to each effect.

**The rows of a law** are ``compare`` rows (variants, :mod:`twolink_pin.law_variant`), each run
with the report's settings over :data:`PERIODS` period of the reference, **started on it**
(``--q0-offset 0``: no initial transient, so that what an effect does to the tracking is what
the numbers show; at most the report's duration):

* ``LAW`` — the report's plant (Pinocchio's, the report's friction and options);
* ``LAW@plant=mujoco@soft_limits=off`` — the same arm on MuJoCo with every effect off: the
  same run to rounding (:mod:`twolink_pin.mujoco_plant`), the section's check that a difference
  below comes from an effect and not from the simulator;
* one row per effect the arm has (:func:`arm_effects`, :mod:`twolink_pin.arm_effects`): that
  effect alone on MuJoCo (its armature, joint damping or dry friction, ``arm``: the robot's
  profile, else its URDF; its soft limits; the effort clamp when the report does not clip; MuJoCo's
  ``implicitfast`` integrator with the law held over each step);
* ``…@plant=mujoco`` with every effect at once.

By default the no-effect check and each effect alone are run on the report's first law only
(:func:`alone_on`): the other laws have their first and last rows (Pinocchio, every effect).
``ReportOptions.sim_to_sim_all`` (``report --sim-to-sim-all``) runs every row of every law.

An effect that cannot act on the run is not run again: soft limits on a run that never reaches a
joint's range, the effort clamp on a commanded torque below :data:`CLAMP_MARGIN` of every limit
(:func:`inactive`; MuJoCo with no effect is that run until the effect acts). Its row repeats the
no-effect row's numbers and says why (``derived``). The section costs what
``PERIODS × (3 + effects acting)`` periods of a law with every row cost, ``PERIODS × 2`` of the
others (on the twolink, 15 runs of one period by default, 35 with every row of every law: a row
is the same run in both).

**The numbers** are :func:`~twolink_pin.metrics.compute_metrics`' per-joint ones, as ``compare``'s
table has them: ``RMS ‖e‖ = (Σ_j RMS(e_j)²)^½`` [rad] and ``max |e|`` [rad], the largest
``|e_j(t)|`` of any joint, over the run; and each row's difference from the first (Δ). An effect's Δ is what it alone changes; the
sum of the one-effect Δs need not be the all-effects Δ (the effects interact). A run that fails
is a row saying when.

:func:`sim_to_sim_law` is one worker task (picklable arguments only), one law's rows;
:func:`submit` hands them to the report's pool, :func:`collect` assembles the section as
``results.json`` holds it under ``sim_to_sim`` (with its figure).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.arm_effects import ARM, UNITS, resolve_effect
from twolink_pin.errors import ControllerError, InvalidParameterError, SimulationDivergedError
from twolink_pin.law_variant import Variant, parse_variant
from twolink_pin.limits import POSITION, joint_limits
from twolink_pin.metrics import compute_metrics
from twolink_pin.report.options import ReportOptions
from twolink_pin.report.runs import reference_trajectory
from twolink_pin.simulation import SimulationConfig, simulate

PERIODS = 1
"""The section's runs: this many periods of the reference, started on it."""
MUJOCO = "@plant=mujoco"
"""The settings that put a row on MuJoCo."""
NO_EFFECT = MUJOCO + "@soft_limits=off"
"""MuJoCo with every effect off (its soft limits are on by default)."""
FIGURE = "sim_to_sim.png"
"""The section's figure (``figures/``): each effect's Δ RMS ‖e‖ per law."""

__all__ = [
    "CLAMP_MARGIN",
    "FIGURE",
    "MUJOCO",
    "NO_EFFECT",
    "PERIODS",
    "alone_on",
    "arm_effects",
    "collect",
    "inactive",
    "row_texts",
    "section_config",
    "sim_to_sim_law",
    "skipped",
    "submit",
]


def arm_effects(robot: Any, options: ReportOptions) -> list[dict[str, str]]:
    """The effects ``robot`` has that the report's plant leaves out, each as ``{"key", "short",
    "label", "setting"}`` (``setting``: the variant setting that turns it on): the per-joint ones
    the arm gives a value of, soft limits where a joint has a range, the effort clamp where a
    joint has a limit and the report does not clip, and MuJoCo's ``implicitfast``."""
    plant = options.run.plant
    found = []
    for name, short in (
        ("armature", "armature"),
        ("joint_damping", "joint damping"),
        ("frictionloss", "dry friction"),
    ):
        if getattr(plant, name) is not None:
            continue
        try:
            values, source = resolve_effect(robot, name, ARM)
        except InvalidParameterError:  # the arm gives none
            continue
        shown = ", ".join(f"{x:g}" for x in values)
        label = f"{short} ({shown}) {UNITS[name]}, {source}"
        found.append(_effect(name, short, label, f"@{name}={ARM}"))
    if joint_limits(robot).given(POSITION).any():
        label = "soft joint limits (MuJoCo's default solref, solimp)"
        found.append(_effect("soft_limits", "soft limits", label, "@soft_limits=on"))
    if not plant.saturate and np.isfinite(robot.torque_limits).any():
        found.append(_effect("saturate", "effort clamp", "effort clamp at the URDF limits", "@saturate=on"))
    label = "MuJoCo's implicitfast, the law held over each step"
    found.append(_effect("integrator", "implicitfast", label, "@integrator=implicitfast"))
    return found


def _effect(key: str, short: str, label: str, setting: str) -> dict[str, str]:
    return {"key": key, "short": short, "label": label, "setting": setting}


def row_texts(
    variant: Variant, effects: list[dict[str, str]], alone: bool = True
) -> list[tuple[str, str, str]]:
    """``(row label, short label, variant text)`` of each row of ``variant``'s law (module
    docstring); without ``alone``, only the first and the last (Pinocchio, every effect)."""
    base = variant.text
    rows = [("Pinocchio (the report's plant)", "Pinocchio", base)]
    if alone:
        rows.append(("MuJoCo, no effect", "MuJoCo, no effect", base + NO_EFFECT))
    for effect in effects if alone else ():
        off = "" if effect["key"] == "soft_limits" else "@soft_limits=off"
        rows.append(
            (f"MuJoCo + {effect['label']}", f"+ {effect['short']}", base + MUJOCO + off + effect["setting"])
        )
    every = "".join(e["setting"] for e in effects if e["key"] != "soft_limits")
    soft = "" if any(e["key"] == "soft_limits" for e in effects) else "@soft_limits=off"
    rows.append(("MuJoCo + every effect", "+ every effect", base + MUJOCO + soft + every))
    return rows


def _numbers(text: str, options: ReportOptions, robot: Any, trajectory: Any) -> dict[str, Any]:
    """One row's run (module docstring): its ``RMS ‖e‖`` and ``max |e|`` [rad], how far it went
    (each joint's position range and largest commanded torque), or what stopped it."""
    spec = options.run.for_law(parse_variant(text))
    spec = dataclasses.replace(spec, simulation=section_config(spec.simulation, trajectory))
    controller, plant = spec.build(robot)
    try:
        result = simulate(controller, plant, trajectory, spec.simulation)
    except (SimulationDivergedError, ControllerError) as exc:
        return {"finished": False, "failed": str(exc)}
    metrics = compute_metrics(result)
    return {
        "finished": True,
        "rms_e": float(np.sqrt(np.sum(np.square(metrics.rms.e)))),
        "max_e": float(np.max(metrics.max.e)),
        "rms_e_joints": np.asarray(metrics.rms.e).tolist(),
        "max_e_joints": np.asarray(metrics.max.e).tolist(),
        "plant": plant.describe(),
        "reach": {
            "q_min": result.q.min(axis=0).tolist(),
            "q_max": result.q.max(axis=0).tolist(),
            "tau_peak": np.abs(result.tau_command).max(axis=0).tolist(),
        },
    }


def section_config(config: SimulationConfig, trajectory: Any) -> SimulationConfig:
    """The section's run settings: the report's, over :data:`PERIODS` periods of the reference (at
    most the report's duration), starting on the reference."""
    duration = min(PERIODS * float(trajectory.period), config.duration)
    return dataclasses.replace(config, duration=duration, q0_offset=0.0, v0_offset=0.0)


CLAMP_MARGIN = 0.9
"""The effort clamp cannot act when the run's commanded torque stays below this fraction of every
limit at its samples (within a 1-ms step a law's torque does not grow by a tenth)."""


def inactive(key: str, robot: Any, plain: dict[str, Any]) -> str | None:
    """Why effect ``key`` cannot act on the run ``plain`` (MuJoCo with no effect, the run it equals
    until the effect acts), or None: soft limits a run that never reaches a range, the clamp a
    commanded torque below :data:`CLAMP_MARGIN` of every limit."""
    if not plain["finished"]:
        return None
    reach = plain["reach"]
    if key == "soft_limits":
        bounds = joint_limits(robot)
        lower, upper = np.asarray(bounds.position_lower), np.asarray(bounds.position_upper)
        if (np.asarray(reach["q_min"]) > lower).all() and (np.asarray(reach["q_max"]) < upper).all():
            return "the run never reaches a joint's range: the soft limits cannot act (the no-effect run)"
    if key == "saturate":
        if (np.asarray(reach["tau_peak"]) < CLAMP_MARGIN * np.asarray(robot.torque_limits)).all():
            return (
                f"its commanded torque stays below {CLAMP_MARGIN:.0%} of every effort limit: the clamp "
                "cannot act (the no-effect run)"
            )
    return None


def sim_to_sim_law(name: str, variant: Variant, options: ReportOptions, alone: bool = True) -> dict[str, Any]:
    """Worker: the rows of one law of the report (module docstring); with ``alone`` all of them,
    else Pinocchio's and every effect's."""
    start, cpu = time.perf_counter(), time.process_time()
    robot = options.load_robot()
    trajectory = reference_trajectory(robot, options)
    effects = arm_effects(robot, options)
    keys = {f"MuJoCo + {e['label']}": e["key"] for e in effects}
    rows: list[dict[str, Any]] = []
    for label, short, text in row_texts(variant, effects, alone):
        row: dict[str, Any] = {"row": label, "short": short, "variant": text}
        why = inactive(keys.get(label, ""), robot, rows[1]) if len(rows) > 1 else None
        if why is None:
            row |= _numbers(text, options, robot, trajectory)
        else:  # the no-effect run's numbers: the run it would be
            row |= {k: v for k, v in rows[1].items() if k not in row} | {"derived": why}
        rows.append(row)
    first = rows[0]
    for row in rows:
        if row["finished"] and first["finished"]:
            row["delta_rms_e"] = row["rms_e"] - first["rms_e"]
            row["delta_max_e"] = row["max_e"] - first["max_e"]
    return {
        "law": name,
        "effects_alone": alone,
        "rows": rows,
        "duration_s": section_config(options.run.simulation, trajectory).duration,
        "seconds": time.perf_counter() - start,
        "cpu_seconds": time.process_time() - cpu,
    }


def skipped(options: ReportOptions, variants: list[tuple[str, Variant]]) -> str | None:
    """Why the report has no such section (its runs on MuJoCo already, or a law with plant
    settings of its own), or None."""
    if options.run.plant.engine != "pinocchio":
        return f"the report's runs are on {options.run.plant.engine} already"
    own = [name for name, variant in variants if variant.plant]
    if own:
        return f"{', '.join(own)} set their own plant"
    return None


def alone_on(options: ReportOptions, names: list[str]) -> list[str]:
    """The laws (of the report's ``names``) with every row (the no-effect check, each effect
    alone): every one with ``options.sim_to_sim_all``, else the first (what each effect does is
    shown once; every law runs on Pinocchio and with every effect)."""
    return list(names) if options.sim_to_sim_all else list(names[:1])


def submit(pool: Any, variants: list[tuple[str, Variant]], options: ReportOptions) -> dict[str, Any] | str:
    """Each law's rows submitted to the report's worker ``pool`` (law → future), or why the
    report has no such section (:func:`skipped`); each effect alone on the laws :func:`alone_on`
    names."""
    why = skipped(options, variants)
    if why is not None:
        return why
    alone = alone_on(options, [name for name, _ in variants])
    return {
        name: pool.submit(sim_to_sim_law, name, variant, options, name in alone) for name, variant in variants
    }


def collect(
    pending: dict[str, Any] | str, robot: Any, options: ReportOptions, fig_dir: str, heard: int
) -> dict[str, Any]:
    """The section as ``results.json`` holds it under ``sim_to_sim``: each law's rows (waited
    for), the effects and their sources, the figure; or only a note when :func:`submit` gave one."""
    from twolink_pin import interrupts
    from twolink_pin.plotting.sim_to_sim import save_sim_to_sim_figure

    effects = arm_effects(robot, options)
    sources = robot.profile.effects.source if robot.profile.effects is not None else ""
    section: dict[str, Any] = {
        "periods": PERIODS,
        "all": options.sim_to_sim_all,
        "effects": effects,
        "sources": sources,
        "laws": [],
        "figure": None,
    }
    if isinstance(pending, str):
        return section | {"note": f"no sim-to-sim section: {pending}"}
    laws = [interrupts.result_of(future, heard) for future in pending.values()]
    alone = [law["law"] for law in laws if law["effects_alone"]]
    which = (
        "" if len(alone) == len(laws) else f"; each effect alone: {', '.join(alone)}, the others every effect"
    )
    title = f"{robot.name}: what each effect on MuJoCo changes (one period, started on the reference{which})"
    figure = save_sim_to_sim_figure(laws, Path(fig_dir) / FIGURE, title).name
    return section | {
        "effects_alone": alone,
        "duration_s": laws[0]["duration_s"] if laws else None,
        "laws": laws,
        "figure": figure,
        "seconds": sum(law["seconds"] for law in laws),
        "cpu_seconds": sum(law["cpu_seconds"] for law in laws),
    }
