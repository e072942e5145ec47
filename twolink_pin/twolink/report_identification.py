"""The twolink report's identification section (beside Fig. 27): the adaptive law along
the excitations, an identification from one logged run, their figures and numbers.

Called by :class:`twolink_pin.twolink.course_report.CourseReport` (the twolink profile's
report hook); the tasks run in the report's worker processes (picklable arguments only)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.report.options import ReportOptions

IDENTIFICATION_NOISE = (1e-5, 0.05)
"""Noise of the report's identification example: σ_q [rad] (encoder level), σ_τ [N·m]."""


def _finite(x: Any) -> Any:
    """``x`` with non-finite floats as None (results.json is strict JSON)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if np.isfinite(x) else None
    return x


def _reuses_adaptive_run(options: ReportOptions) -> bool:
    """Whether the report's ``adaptive`` run is exactly the identification section's run
    along the report's trajectory (same law, gains, p̂(0), reference and simulation)."""
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationConfig

    duration = options.run.simulation.duration  # the one setting the section follows
    return options.trajectory is None and options.run == RunSpec(
        shared=True, simulation=SimulationConfig(duration=duration)
    )


def _submit_identification(
    pool: Any, options: ReportOptions, fig_dir: str, reused: bool
) -> tuple[dict[str, Any], Any] | None:
    """Submit the identification section's tasks: the report's adaptive law along each
    reference (one task each; not along the report's trajectory when ``reused``: the
    report's own adaptive run is that one) and the identification from a logged run."""
    from twolink_pin.twolink import excitation as twolink_excitation

    if options.run.simulation.duration < twolink_excitation.PERIOD:
        return {}, None
    keys = [key for key in twolink_excitation.TRAJECTORIES if not (reused and key == "report")]
    runs = {key: pool.submit(_excitation_run, options, key) for key in keys}
    return runs, pool.submit(_identification_fit, options, fig_dir)


def _excitation_run(options: ReportOptions, key: str) -> tuple[np.ndarray, np.ndarray]:
    """Worker: the report's adaptive law along the reference ``key``: ``(t [s], p̂)``."""
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = options.load_robot()
    result = twolink_excitation.adaptive_runs(robot, duration=options.run.simulation.duration, keys=(key,))[
        key
    ]
    assert result.p_hat is not None
    return np.asarray(result.t), np.asarray(result.p_hat)[:, : np.asarray(robot.p).size]


def _identification_fit(options: ReportOptions, fig_dir: str) -> tuple[list[str], dict[str, Any]]:
    """Worker: identification from one noisy logged run along the identification excitation,
    its figures and its numbers."""
    from twolink_pin.identification import (
        ExcitationLimits,
        IdentifiedParameters,
        add_noise,
        identify,
        map_parameters,
        simulate_log,
    )
    from twolink_pin.plotting.identification import save_excitation_figures, save_identification_figures
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = options.load_robot()
    p = np.asarray(robot.p, dtype=float)
    log = simulate_log(
        robot, twolink_excitation.identification_excitation(), duration=options.run.simulation.duration
    )
    noisy = add_noise(log, *IDENTIFICATION_NOISE, seed=0)
    found = identify(noisy, robot)
    figures = list(save_identification_figures(found, fig_dir))
    limits = ExcitationLimits().resolve(robot)
    figures += save_excitation_figures(
        robot,
        twolink_excitation.identification_excitation(),
        fig_dir,
        limits={k: v.tolist() for k, v in limits.items()},
    )
    nb = found.size - 2 * robot.nv
    identified = IdentifiedParameters("report", found.estimate[:nb], found.std[:nb], None)
    p_identified = map_parameters(robot, identified)
    inside = found.within()
    numbers = {
        "noise": {"q_rad": IDENTIFICATION_NOISE[0], "tau_Nm": IDENTIFICATION_NOISE[1], "seed": 0},
        "parameters": found.parameters(),
        "condition_number": found.condition_number,
        "validation_rms": None if found.validation is None else found.validation.rms.tolist(),
        "fit_samples": found.fit_samples,
        "cutoff_hz": found.cutoff_hz,
        "within_3_sigma": None if inside is None else int(np.sum(inside)),
        "method": found.method,
        "p": p_identified.tolist(),
        "p_relative_error": (np.abs(p_identified - p) / np.abs(p)).tolist(),
    }
    return [str(f) for f in figures], numbers


def _identification_section(
    options: ReportOptions,
    fig_dir: str,
    runs: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
    fit: tuple[list[str], dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """The report's question answered beside Figure 27 (the twolink only): why the adaptive
    estimates are still far from p at the end of the run, the excitations that fix it, and
    what identification gives from one run of the same length. ``runs`` (key → (t, p̂)) and
    ``fit`` are the results of :func:`_excitation_run` and :func:`_identification_fit`, run
    here when not given.

    The adaptive runs and the identification need a run of at least one excitation period;
    shorter reports show the table only."""
    from twolink_pin.identification.measures import averaged_adaptation
    from twolink_pin.plotting.identification import save_convergence_figure
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = options.load_robot()
    duration = options.run.simulation.duration
    section: dict[str, Any] = {
        "table": twolink_excitation.excitation_table(robot),
        "duration_s": duration,
        "period_s": twolink_excitation.PERIOD,
        "figures": [],
        "runs": {},
        "identified": None,
        "note": None,
    }
    if duration < twolink_excitation.PERIOD:
        section["note"] = (
            f"runs of {duration:g} s are shorter than one excitation period ({twolink_excitation.PERIOD:g} s): "
            "the adaptive runs along the excitations and the identification are left out"
        )
        return _finite(section)
    if not runs:
        runs = {key: _excitation_run(options, key) for key in twolink_excitation.TRAJECTORIES}
    if fit is None:
        fit = _identification_fit(options, fig_dir)
    controller = twolink_excitation.report_adaptive(robot).controller
    p = np.asarray(robot.p, dtype=float)
    panels = {}
    for key, (t, p_hat) in runs.items():
        within = twolink_excitation.time_within(t, p_hat, p)
        averaged = averaged_adaptation(controller, twolink_excitation.trajectories(robot)[key])
        t_pred = np.linspace(0.0, duration, 301)
        predicted = averaged.predicted_error(p_hat[0] - p, t_pred)
        section["runs"][key] = {
            "title": twolink_excitation.TITLES[key],
            "p_hat_final": p_hat[-1].tolist(),
            "relative_error_final": (np.abs(p_hat[-1] - p) / np.abs(p)).tolist(),
            "time_within_5_percent_s": within,
        }
        panels[twolink_excitation.TITLES[key]] = {
            "t": t,
            "p_hat": p_hat,
            "p_true": p,
            "names": list(robot.parameter_map.names),
            "predicted": (t_pred, predicted),
            "time_within": within,
            "note": f"averaged slowest time constant {averaged.slowest_time_constant:.3g} s",
        }
    figures: list[str | Path] = [
        save_convergence_figure(
            panels,
            Path(fig_dir) / "identification_convergence.png",
            title="the report's adaptive law (K = 120, γ = (0.5, 0.15, 0.6)) along three references — cf. report "
            "Fig. 27\n|p̂ − p| / |p| (solid: simulated; dotted: averaged model exp(−ΓG t))",
        ),
        *fit[0],
    ]
    section["identified"] = fit[1]
    section["figures"] = [Path(f).name for f in figures]
    return _finite(section)
