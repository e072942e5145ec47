"""``identify`` and ``excite``: parameters from a run or a log, and the excitation that
identifies them best."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twolink_pin.cli.commands.common import robot_from_args
from twolink_pin.cli.output import emit, fmt, progress_bar
from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    from twolink_pin.identification import RunLog
    from twolink_pin.identification.excitation import Excitation, ExcitationDesign
    from twolink_pin.identification.measures import ExcitationMeasures
    from twolink_pin.model import RobotModel
    from twolink_pin.trajectory import Trajectory


def _excitation(robot: RobotModel) -> tuple[Trajectory, str]:
    """The robot's excitation and where it came from (stored, or optimised now)."""
    from twolink_pin.identification.excitation import optimise_excitation, stored_excitation

    stored = stored_excitation(robot)
    if stored is not None:
        return stored, "stored excitation"
    print(
        f"twolink-pin: optimising an excitation for {robot.name} (none is stored): this can take minutes; "
        "save one with twolink-pin excite --out FILE and pass --trajectory FILE",
        file=sys.stderr,
        flush=True,
    )
    return optimise_excitation(robot).trajectory, "excitation optimised now"


def _data_log(args: argparse.Namespace, robot: RobotModel) -> tuple[RunLog, str, Any]:
    """``--data``: the user's log (CSV/NPZ, or a ROS bag with its summary), checked; the
    refusals of options that only shape a simulated run."""
    from twolink_pin.identification import read_log

    plant = getattr(args, "plant", "pinocchio")
    given = [
        name
        for name, value in (("--duration", args.duration), ("--dt", args.dt), ("--plant", plant))
        if value not in (None, "pinocchio")
    ]
    if given:
        raise InvalidParameterError(
            given[0],
            getattr(args, given[0][2:]),
            "no value with --data (it shapes a simulated run only)",
        )
    from twolink_pin.identification.bags import DEFAULT_TOPIC, is_bag, read_bag

    bag_summary = None
    if is_bag(args.data):
        joints = [str(n) for n in robot.model.names[1:]]
        log, bag_summary = read_bag(args.data, joints, args.topic or DEFAULT_TOPIC, args.torque_topic)
    else:
        if args.topic or args.torque_topic:
            raise InvalidParameterError(
                "--topic" if args.topic else "--torque-topic",
                args.topic or args.torque_topic,
                "no topic with a CSV/NPZ log (topics are for ROS bags: a folder, .db3, .mcap or .bag)",
            )
        log = read_log(args.data, robot.nv)
    from twolink_pin.identification.diagnostics import check_log

    check_log(log, robot)
    reference = f"data {args.data}"
    if args.reference:
        from dataclasses import replace

        from twolink_pin.trajectory import read_trajectory_file

        log = replace(log, reference=read_trajectory_file(args.reference, robot))
        reference += f", reference {args.reference}"
    return log, reference, bag_summary


def _simulated_log(args: argparse.Namespace, robot: RobotModel) -> tuple[RunLog, str]:
    """No ``--data``: a simulated run along ``--trajectory`` or the robot's excitation; the
    refusals of options that only apply to a log."""
    from twolink_pin.identification import simulate_log
    from twolink_pin.identification.simulated import DEFAULT_DT
    from twolink_pin.trajectory import read_trajectory_file

    if args.reference or args.topic or args.torque_topic:
        flag = "--reference" if args.reference else "--topic" if args.topic else "--torque-topic"
        raise InvalidParameterError(
            flag, getattr(args, flag[2:].replace("-", "_")), "a value only with --data (a log of yours)"
        )
    if args.trajectory:
        trajectory: Trajectory = read_trajectory_file(args.trajectory, robot)
        reference = f"trajectory {args.trajectory}"
    else:
        trajectory, reference = _excitation(robot)
    log = simulate_log(
        robot,
        trajectory,
        duration=args.duration,
        dt=DEFAULT_DT if args.dt is None else args.dt,
        engine=getattr(args, "plant", "pinocchio"),
    )
    return log, reference


def _physical_and_urdf(
    args: argparse.Namespace,
    log: RunLog,
    robot: RobotModel,
    options: Any,
    result: Any,
    document: dict[str, Any],
) -> list[str]:
    """``--physical`` (the constrained fit, into ``document``) and ``--write-urdf``; their lines."""
    physical_lines: list[str] = []
    fit = None
    if args.physical:
        from twolink_pin.identification.physical import compare_physical

        physical_document, physical_lines, fit = compare_physical(log, robot, options, result)
        document["parameters"] = physical_document.pop("parameters")  # what --save gives --model
        document["physical"] = physical_document
    if args.write_urdf:
        from twolink_pin.identification.physical import write_identified_urdf

        write_identified_urdf(args.write_urdf, robot, result.estimate, options.friction, fit)
        document["urdf_written"] = args.write_urdf
        physical_lines.append(
            f"  URDF with the identified inertias{' and friction (<dynamics>)' if options.friction else ''} "
            f"written to {args.write_urdf} (as the model a law believes: --model {args.write_urdf}; as the "
            f"plant: --robot {args.write_urdf})"
        )
    return physical_lines


def _result_lines(
    args: argparse.Namespace, robot: RobotModel, log: RunLog, result: Any, reference: str, within: Any
) -> list[str]:
    """The fit as text: source, method, filter, one row per parameter, conditioning, ±3σ."""
    lines = [
        f"identified {result.size} parameters of {robot.name} from {log.source}",
        f"  {reference}; {result.fit_samples} samples fitted (every {result.stride}th valid one of {result.samples}, "
        f"{result.fit_interval[0]:.3g}–{result.fit_interval[1]:.3g} s)"
        + (
            ""
            if result.validation is None
            else f"; validation {result.validation.t[0]:.3g}–{result.validation.t[-1]:.3g} s"
        ),
        f"  {'weighted ' if result.weighted else ''}{result.method}"
        + (" (instruments: the reference motion's regressor)" if result.method != "least squares" else ""),
        f"  filter: zero-phase Butterworth order {result.order}, cut-off {result.cutoff_hz:g} Hz at "
        f"{1 / result.dt:.6g} Hz; {result.guard:.3g} s dropped at each end"
        + (" (log resampled to a uniform grid)" if result.resampled else ""),
        f"  {'parameter':44s} {'estimate':>14s} {'± σ':>10s} {'σ/|θ|':>8s}"
        + (f" {'true':>14s}" if result.true is not None else ""),
    ]
    for row in result.parameters():
        name = f"{row['name']} [{row['unit']}]"
        rel = "—" if row["relative_std_percent"] is None else f"{row['relative_std_percent']:.3g}%"
        true = "" if row["true"] is None else f" {row['true']:14.8g}"
        lines.append(f"  {name[:44]:44s} {row['estimate']:14.8g} {row['std']:10.3g} {rel:>8s}{true}")
    lines.append(
        f"  condition number {result.condition_number:.4g} (weighted {result.weighted_condition_number:.4g}); "
        f"residual RMS {fmt(result.residual_rms, 4)} N·m"
        + ("" if result.validation is None else f"; validation RMS {fmt(result.validation.rms, 4)} N·m")
    )
    if within is not None:
        noise_free = args.data is None and not args.noise_q and not args.noise_tau
        lines.append(
            f"  true values within ±3σ: {int(within.sum())} of {within.size}"
            + (
                " (noise-free data: σ and the errors are rounding and filtering, not a test of σ; "
                "add --noise-q/--noise-tau)"
                if noise_free
                else ""
            )
        )
    return lines


def cmd_identify(args: argparse.Namespace) -> int:
    from twolink_pin.files import write_json
    from twolink_pin.identification import (
        IdentificationOptions,
        ZeroPhaseFilter,
        add_noise,
        identification_document,
        identify,
        write_log,
    )

    robot = robot_from_args(args)
    if args.data:
        log, reference, bag_summary = _data_log(args, robot)
    else:
        bag_summary = None
        log, reference = _simulated_log(args, robot)
    log = add_noise(log, args.noise_q, args.noise_tau, args.seed)
    options = IdentificationOptions(
        zero_phase=ZeroPhaseFilter(args.cutoff, args.order, reversal_guard=args.reversal_guard),
        friction=not args.no_friction,
        validation=args.validation,
        weighted=not args.ols,
        instruments=not args.no_instruments,
    )
    result = identify(log, robot, options)
    document = identification_document(result, robot)
    physical_lines = _physical_and_urdf(args, log, robot, options, result, document)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting.identification import save_identification_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_identification_figures(result, folder)]
    if args.save:
        write_json(args.save, document)
    if args.save_data:
        write_log(args.save_data, log)
    within = result.within(3.0)
    document |= {
        "reference": reference,
        "noise": {"q_rad": args.noise_q, "tau_Nm": args.noise_tau, "seed": args.seed},
        "within_3_sigma": None if within is None else within.tolist(),
        "figures": figures,
        "saved": args.save,
        "data_saved": args.save_data,
    }
    lines = [] if bag_summary is None else bag_summary.lines()
    lines += _result_lines(args, robot, log, result, reference, within)
    from twolink_pin.identification.diagnostics import fit_warnings

    warnings = fit_warnings(result)
    document["warnings"] = warnings
    lines += [f"  {w}" for w in warnings]
    lines += physical_lines
    lines += [f"  figure {f}" for f in figures]
    if args.save:
        lines.append(f"  parameters saved to {args.save} (use with --p0 / --model)")
    if args.save_data:
        lines.append(f"  log saved to {args.save_data}")
    emit(args, document, "\n".join(lines))
    return 0


def cmd_excite(args: argparse.Namespace) -> int:
    from twolink_pin.identification import optimise_excitation
    from twolink_pin.identification.excitation_check import check_excitation_work, excitation_problem
    from twolink_pin.identification.measures import excitation_measures
    from twolink_pin.trajectory import default_trajectory, write_trajectory_file

    robot = robot_from_args(args)
    if Path(args.out).suffix.lower() not in (".json", ".toml"):
        raise InvalidParameterError("--out", args.out, "a trajectory file name ending in .json or .toml")
    design = _excitation_design(args)
    check_excitation_work(robot.nv, args.harmonics, args.samples, args.starts, args.max_iterations)
    bar = progress_bar(args.starts * args.max_iterations, "it", f"excite {robot.name}")
    with bar:
        excitation = optimise_excitation(robot, design, progress=lambda done, total: bar.update(done - bar.n))
    problem = excitation_problem(excitation.peaks, excitation.limits)
    if problem:  # an infeasible or motionless excitation is a failed run, never a saved success
        print(f"twolink-pin: excite failed: {problem}; nothing written to {args.out}", file=sys.stderr)
        return 1
    written = write_trajectory_file(args.out, excitation.trajectory)
    default = excitation_measures(robot, default_trajectory(robot))
    payload = _excitation_payload(robot, design, excitation, written, default)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting.identification import save_excitation_figures

        with removed_on_failure(args.plot) as folder:
            figures = [
                str(p)
                for p in save_excitation_figures(
                    robot, excitation.trajectory, folder, limits=excitation.limits
                )
            ]
    payload["figures"] = figures
    emit(args, payload, "\n".join(_excitation_lines(robot, design, excitation, written, default, payload)))
    return 0


def _excitation_design(args: argparse.Namespace) -> ExcitationDesign:
    """The design ``excite``'s options ask for (harmonics, period, criterion, optimiser, limits)."""
    from twolink_pin.identification import ExcitationDesign, ExcitationLimits

    limits = ExcitationLimits(
        position_margin=args.position_margin,
        velocity_fraction=args.velocity_fraction,
        acceleration=args.acceleration,
        torque_fraction=args.torque_fraction,
    )
    return ExcitationDesign(
        harmonics=args.harmonics,
        period=args.period,
        criterion=args.criterion,
        samples=args.samples,
        starts=args.starts,
        max_iterations=args.max_iterations,
        seed=args.seed,
        limits=limits,
    )


def _excitation_payload(
    robot: RobotModel,
    design: ExcitationDesign,
    excitation: Excitation,
    written: Path,
    default: ExcitationMeasures,
) -> dict[str, Any]:
    """``excite --json``: the excitation's measures beside the ``default`` trajectory's, the
    optimiser's account, the verdict, the peaks, the Fourier table and the adaptive law's
    slowest averaged time constants [s] on both trajectories (``figures`` added later)."""
    from twolink_pin.identification.excitation_check import excitation_verdict
    from twolink_pin.identification.measures import averaged_adaptation
    from twolink_pin.trajectory import default_trajectory

    payload: dict[str, Any] = {
        "robot": robot.name,
        "file": str(written),
        "criterion": excitation.criterion,
        "condition_number": excitation.measures.condition_number,
        "gram_min_eigenvalue": excitation.measures.gram_min_eigenvalue,
        "gram_min_eigenvalue_per_s": excitation.measures.gram_min_eigenvalue_per_s,
        "default_trajectory_condition_number": default.condition_number,
        "default_trajectory_gram_min_eigenvalue_per_s": default.gram_min_eigenvalue_per_s,
        "parameters": list(excitation.measures.names),
        "seconds": excitation.seconds,
        "iterations": excitation.iterations,
        "evaluations": excitation.evaluations,
        "starts": excitation.starts,
        "seed": design.seed,
        "success": excitation.success,
        "converged": excitation.converged,
        "verdict": excitation_verdict(
            excitation.peaks, excitation.limits, excitation.converged, excitation.message
        ),
        "message": excitation.message,
        "design": {"harmonics": design.harmonics, "period_s": design.period, "samples": design.samples},
        "limits": excitation.limits,
        "peaks": excitation.peaks,
        "fourier": excitation.trajectory.as_dict(),
    }
    if robot.name == "twolink":
        payload["report_condition_number"] = default.condition_number
    try:
        from twolink_pin.run_spec import make_scenario

        law = make_scenario("adaptive", robot).controller
        payload["adaptive_slowest_time_constant_s"] = averaged_adaptation(
            law, excitation.trajectory
        ).slowest_time_constant
        payload["default_trajectory_adaptive_slowest_time_constant_s"] = averaged_adaptation(
            law, default_trajectory(robot)
        ).slowest_time_constant
    except InvalidParameterError:  # pragma: no cover - the built-in adaptive law always applies
        pass
    return payload


def _excitation_lines(
    robot: RobotModel,
    design: ExcitationDesign,
    excitation: Excitation,
    written: Path,
    default: ExcitationMeasures,
    payload: dict[str, Any],
) -> list[str]:
    """``excite``'s text: the design, the optimiser's account, the verdict, the measures beside
    the default trajectory's, the peaks and the figures."""
    from twolink_pin.identification.excitation_check import excitation_verdict

    which = "the report's trajectory" if robot.name == "twolink" else "the default trajectory"
    lines = [
        f"excitation for {robot.name} ({design.criterion}): {design.harmonics} harmonics, period {design.period:g} s "
        f"-> {written}",
        f"  optimiser: SLSQP from {design.starts} seeded starts (seed {design.seed}), {excitation.iterations} iterations, "
        f"{excitation.evaluations} evaluations, {excitation.seconds:.1f} s; {excitation.message}",
        "  "
        + excitation_verdict(excitation.peaks, excitation.limits, excitation.converged, excitation.message),
        f"  cond(W) of {len(excitation.measures.names)} parameters (base + friction) over a period: "
        f"{excitation.measures.condition_number:.4g}; {which}: {default.condition_number:.4g}",
        f"  smallest Gram eigenvalue per second {excitation.measures.gram_min_eigenvalue_per_s:.4g}; {which}: "
        f"{default.gram_min_eigenvalue_per_s:.4g}",
    ]
    if "adaptive_slowest_time_constant_s" in payload:
        lines.append(
            f"  adaptive law's slowest averaged time constant {payload['adaptive_slowest_time_constant_s']:.4g} s; "
            f"{which}: {payload['default_trajectory_adaptive_slowest_time_constant_s']:.4g} s"
        )
    peaks = excitation.peaks
    lines.append(
        f"  peaks |q̇| {fmt(peaks['v_max'], 3)} rad/s, |q̈| {fmt(peaks['a_max'], 3)} rad/s², |τ| {fmt(peaks['tau_max'], 3)} N·m"
    )
    lines += [f"  figure {f}" for f in payload["figures"]]
    return lines
