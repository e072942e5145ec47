"""The commands of ``twolink-pin``: each a thin shell over the library.

Every command prints a readable summary, or JSON with ``--json``. The library is imported
inside each command, so ``--help`` stays fast.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.cli.output import emit, fmt, progress_bar
from twolink_pin.errors import InvalidParameterError

if TYPE_CHECKING:
    from twolink_pin.identification import IdentifiedParameters
    from twolink_pin.metrics import Metrics
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationConfig, SimulationResult
    from twolink_pin.trajectory import Trajectory


def _robot(args: argparse.Namespace) -> RobotModel:
    from twolink_pin.model import load_robot

    return load_robot(args.robot, payload=getattr(args, "payload", 0.0))


def _trajectory(args: argparse.Namespace, robot: RobotModel) -> Trajectory:
    """The reference of ``--trajectory FILE``, else the robot's default."""
    from twolink_pin.trajectory import default_trajectory, read_trajectory_file

    path = getattr(args, "trajectory", None)
    return read_trajectory_file(path, robot) if path else default_trajectory(robot)


def _config(args: argparse.Namespace) -> SimulationConfig:
    from twolink_pin.simulation import SimulationConfig

    offset = args.q0_offset
    return SimulationConfig(
        duration=args.duration,
        dt=args.dt,
        method=args.method,
        q0_offset=None if offset is None else (offset[0] if len(offset) == 1 else tuple(offset)),
        control_period=args.control_period,
    )


def _smoothing(args: argparse.Namespace) -> float:
    smoothing = args.friction_smoothing
    if smoothing is None:
        smoothing = 1e-3 if args.method == "adaptive" else 0.0
    return float(smoothing)


def _gain_values(texts: list[str]) -> dict[str, Any]:
    """``["kp=200", "kd=30,40"]`` → ``{"kp": 200.0, "kd": (30.0, 40.0)}``."""
    from twolink_pin.cli.arguments import finite

    gains: dict[str, Any] = {}
    for text in texts:
        name, sep, value = text.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise InvalidParameterError("--gain", text, "NAME=VALUE, e.g. kp=200 or kd=30,40")
        try:
            numbers = tuple(finite(x) for x in value.split(","))
        except argparse.ArgumentTypeError as exc:
            raise InvalidParameterError(
                f"--gain {name.strip()}", value, str(exc).removeprefix("expected ")
            ) from None
        gains[name.strip()] = numbers[0] if len(numbers) == 1 else numbers
    return gains


def _identified(args: argparse.Namespace, robot: RobotModel) -> tuple[IdentifiedParameters | None, str]:
    """The parameter file of ``--p0`` or ``--model`` (read once per command) and which it was."""
    mode = "p0" if getattr(args, "p0", None) else "model" if getattr(args, "model", None) else ""
    if not mode:
        return None, ""
    cached = getattr(args, "identified_parameters", None)
    if cached is None:
        from twolink_pin.identification import read_parameter_file

        cached = read_parameter_file(getattr(args, mode), robot)
        args.identified_parameters = cached
        for note in cached.notes:
            print(f"twolink-pin: note: {cached.source}: {note}", file=sys.stderr)
    return cached, mode


def _run_one(
    args: argparse.Namespace, spec: str, robot: RobotModel, trajectory: Trajectory | None = None
) -> SimulationResult:
    from twolink_pin.scenario import law_class, make_scenario
    from twolink_pin.simulation import simulate

    cls = law_class(spec)
    lam = args.lam
    if lam is not None and not cls.takes("lam") and getattr(args, "lambda_optional", False):
        lam = None  # compare/report: λ applies to the laws that have one
    identified, mode = _identified(args, robot)
    several = getattr(args, "lambda_optional", False)  # compare: --p0 seeds the laws that estimate
    if identified is not None and (mode == "model" or cls.estimates or not several):
        from twolink_pin.identification import seeded_scenario

        controller, plant = seeded_scenario(
            cls,
            robot,
            identified,
            mode,
            lam=lam,
            gains=_gain_values(getattr(args, "gain", []) or []),
            saturate=args.saturate,
            friction_smoothing=_smoothing(args),
        )
    else:
        controller, plant = make_scenario(
            cls,
            robot,
            lam=lam,
            gains=_gain_values(getattr(args, "gain", []) or []),
            saturate=args.saturate,
            friction_smoothing=_smoothing(args),
        )
    reference = trajectory if trajectory is not None else _trajectory(args, robot)
    return simulate(controller, plant, reference, _config(args))


def cmd_info(args: argparse.Namespace) -> int:
    from twolink_pin.model.base_parameters import BaseParameterMap

    robot = _robot(args)
    base = (
        robot.parameter_map
        if isinstance(robot.parameter_map, BaseParameterMap)
        else BaseParameterMap(robot.model)
    )
    payload: dict[str, Any] = {
        "robot": robot.name,
        "urdf": str(robot.urdf_path),
        "nq": robot.nq,
        "nv": robot.nv,
        "gravity": robot.model.gravity.linear.tolist(),
        "link_lengths": robot.link_lengths.tolist(),
        "torque_limits": robot.torque_limits.tolist(),
        "parameter_names": list(robot.parameter_map.names),
        "p": robot.p.tolist(),
        "base_parameters": {
            "count": base.size,
            "names": list(base.names),
            "units": list(base.units),
            "values": base.values(robot.model).tolist(),
        },
    }
    if args.friction:
        payload["friction_parameters"] = {
            "names": [f"V{j + 1}" for j in range(robot.nv)] + [f"C{j + 1}" for j in range(robot.nv)],
            "units": ["N·m·s/rad"] * robot.nv + ["N·m"] * robot.nv,
        }
    names = robot.parameter_map.names
    p_text = (
        ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, robot.p))
        if len(names) <= 6
        else f"{len(names)} values"
    )
    limits = ", ".join("no limit" if not np.isfinite(x) else f"{x:g}" for x in robot.torque_limits)
    text = "\n".join(
        [
            f"robot      {robot.name}: {robot.model.name} ({robot.urdf_path})",
            f"joints     nq = {robot.nq}, nv = {robot.nv}; end effector '{robot.ee_frame}'",
            f"gravity    {fmt(robot.model.gravity.linear, 3)} m/s²",
            f"links      {fmt(robot.link_lengths, 3)} m",
            f"limits     ({limits}) N·m",
            f"payload    {robot.payload:g} kg",
            f"parameters {p_text}",
            f"base       {base.size} identifiable base parameters (twolink-pin info --json lists them)"
            + (f", plus {2 * robot.nv} friction (viscous V, Coulomb C per joint)" if args.friction else ""),
        ]
    )
    if args.write_urdf:
        from twolink_pin.model.payload import write_payload_urdf

        if robot.payload <= 0:
            raise InvalidParameterError(
                "--payload", robot.payload, "a mass > 0 kg to write a payload variant"
            )
        target = Path(args.write_urdf)
        if target.exists() and target.resolve() == Path(robot.urdf_path).resolve():
            raise InvalidParameterError(
                "--write-urdf",
                args.write_urdf,
                "a file other than the robot's own URDF (it would be replaced)",
            )
        written = write_payload_urdf(robot.urdf_path, robot.payload, args.write_urdf, robot.ee_frame)
        payload["urdf_written"] = str(written)
        text += f"\nwrote      {written}"
    emit(args, payload, text)
    return 0


def cmd_robots(args: argparse.Namespace) -> int:
    from twolink_pin.model import catalog, load_robot

    rows = []
    for name in catalog.names():
        robot = load_robot(name)
        model = robot.model
        rows.append(
            {
                "name": name,
                "nq": robot.nq,
                "nv": robot.nv,
                "gravity": model.gravity.linear.tolist(),
                "torque_limits": robot.torque_limits.tolist(),
                "end_effector": robot.ee_frame,
                "unlimited_joints": [
                    str(model.names[int(j) + 1]) for j in np.flatnonzero(np.isinf(model.lowerPositionLimit))
                ],
                "locked_joints": list(robot.profile.locked_joints),
                "home": robot.home.tolist(),
                "base_parameters": robot.parameter_map.size if name != "twolink" else 4,
                "description": robot.profile.description,
                "source": robot.profile.source,
            }
        )
    lines = []
    for row in rows:
        limits = ", ".join("none" if not np.isfinite(x) else f"{x:g}" for x in row["torque_limits"])
        notes = []
        if row["unlimited_joints"]:
            notes.append(f"no position limit on {', '.join(row['unlimited_joints'])}")
        if row["locked_joints"]:
            notes.append(f"locked {', '.join(row['locked_joints'])}")
        lines.append(
            f"{row['name']:16s} nq = {row['nq']}, nv = {row['nv']}, gravity {fmt(row['gravity'], 2)} m/s², "
            f"effort limits ({limits}) N·m — {row['description']}"
            + (f"\n{'':16s} {'; '.join(notes)}" if notes else "")
        )
    lines.append(
        "effort limit 'none': the URDF gives none (or 0); no torque check or saturation on that joint"
    )
    emit(args, {"robots": rows}, "\n".join(lines))
    return 0


def cmd_controllers(args: argparse.Namespace) -> int:
    from dataclasses import fields

    from twolink_pin.controllers import available_controllers
    from twolink_pin.controllers.gains import _spec
    from twolink_pin.controllers.loading import broken_plugins

    rows: list[dict[str, Any]] = []
    for name, cls in available_controllers().items():
        gains: list[dict[str, Any]] = [
            {
                "name": f.name,
                "per": _spec(f).per,
                "unit": _spec(f).unit,
                "default": f.default,
                "doc": _spec(f).doc,
            }
            for f in fields(cls.Gains)
        ]
        rows.append(
            {
                "name": name,
                "title": cls.title,
                "class": f"{cls.__module__}:{cls.__qualname__}",
                "estimates": list(cls.estimates),
                "gains": gains,
            }
        )
    lines = []
    for row in rows:
        listed = ", ".join(f"{g['name']}" + (f" [{g['unit']}]" if g["unit"] else "") for g in row["gains"])
        lines.append(f"{row['name']:18s} {row['title']}\n{'':18s} gains: {listed}")
    broken = broken_plugins()
    for problem in broken.values():  # a plug-in that failed to load is not silently missing
        print(f"twolink-pin: warning: {problem}", file=sys.stderr, flush=True)
    emit(args, {"controllers": rows, "broken_plugins": broken}, "\n".join(lines))
    return 0


def cmd_fk(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import joint_positions

    robot = _robot(args)
    q = np.array(args.q, dtype=float)
    if q.shape != (robot.nq,):
        raise InvalidParameterError(
            "Q", args.q, f"{robot.nq} joint angles [rad] for {robot.name} (nq = {robot.nq})"
        )
    position = joint_positions(robot, q)[-1]
    emit(
        args,
        {"position": position.tolist(), "xy": position[:2].tolist()},
        f"end effector at {fmt(position)} m for q = {fmt(q)} rad",
    )
    return 0


def cmd_ik(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import inverse_kinematics, is_planar_2r, solve_position
    from twolink_pin.trajectory import home_configuration

    robot = _robot(args)
    if args.z is None and args.seed is None and is_planar_2r(robot):
        sols = inverse_kinematics(robot, (args.x, args.y))
        text = "\n".join(
            f"{label}: q = {fmt(s)} rad" for label, s in zip(("elbow q2 >= 0", "elbow q2 <= 0"), sols)
        )
        emit(args, {"solutions": sols.tolist()}, text)
        return 0
    target = (args.x, args.y) if args.z is None else (args.x, args.y, args.z)
    seed = home_configuration(robot) if args.seed is None else np.array(args.seed, dtype=float)
    if seed.shape != (robot.nv,):
        raise InvalidParameterError("--seed", args.seed, f"{robot.nv} joint angles [rad] for {robot.name}")
    q = solve_position(robot, target, seed)
    emit(
        args,
        {"solutions": [q.tolist()], "seed": seed.tolist()},
        f"q = {fmt(q)} rad (damped least squares from {'home' if args.seed is None else 'the seed'})",
    )
    return 0


def cmd_trajectory(args: argparse.Namespace) -> int:
    from twolink_pin.feasibility import check_torques
    from twolink_pin.trajectory import FourierTrajectory, JointTrajectory, default_via_points

    robot = _robot(args)
    traj = _trajectory(args, robot)
    via = default_via_points(robot) if not args.trajectory else None
    check = check_torques(robot, traj)
    if isinstance(traj, FourierTrajectory):  # an excitation: no via points, no polynomial
        return _fourier_trajectory(args, robot, traj, check)
    assert isinstance(traj, JointTrajectory)  # the only other kind a file or a profile gives
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_trajectory_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_trajectory_figures(robot, traj, check, folder)]
    payload = {
        "times": traj.times.tolist(),
        "via_xy": None if via is None else [list(p) for p in via.xy],
        "via_q": traj.via_q.tolist(),
        "coefficients": traj.coefficients.tolist(),
        "peak_torque": check.peak.tolist(),
        "peak_time": check.peak_time.tolist(),
        "torque_limits": check.limits.tolist(),
        "margin": check.margin.tolist(),
        "within_limits": check.within_limits,
        "figures": figures,
    }
    lines = ["via points (t [s], q [rad]" + (", end effector (x, y) [m])" if via is not None else ")") + ":"]
    for k, (t, q) in enumerate(zip(traj.times, traj.via_q)):
        lines.append(f"  {t:5.2f}  {fmt(q)}" + (f"  {fmt(via.xy[k], 3)}" if via is not None else ""))
    for j, c in enumerate(traj.coefficients):
        terms = " ".join(f"{x:+.5g}" for x in c)
        lines.append(f"q{j + 1}(t) coefficients, ascending powers of t: {terms}")
    lines.append(f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s")
    lines.append(check.verdict())
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def _fourier_trajectory(args: argparse.Namespace, robot: RobotModel, traj: Any, check: Any) -> int:
    """``trajectory`` for a Fourier-series file: its coefficients, bounds and torque check."""
    from twolink_pin.identification.measures import excitation_measures

    measures = excitation_measures(robot, traj)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting.identification import save_excitation_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_excitation_figures(robot, traj, folder, check=check)]
    q_bound, v_bound, a_bound = traj.bounds
    payload = {
        "fourier": traj.as_dict(),
        "bandwidth_hz": traj.bandwidth,
        "bounds": {"q_minus_offset": q_bound.tolist(), "v": v_bound.tolist(), "a": a_bound.tolist()},
        "condition_number": measures.condition_number,
        "gram_min_eigenvalue_per_s": measures.gram_min_eigenvalue_per_s,
        "peak_torque": check.peak.tolist(),
        "peak_time": check.peak_time.tolist(),
        "torque_limits": check.limits.tolist(),
        "margin": check.margin.tolist(),
        "within_limits": check.within_limits,
        "figures": figures,
    }
    lines = [
        f"Fourier series: period {traj.period:g} s, {traj.harmonics} harmonics (up to {traj.bandwidth:.3g} Hz)",
        f"offsets q0 {fmt(traj.offset)} rad; bounds |q − q0| <= {fmt(q_bound, 3)} rad, |q̇| <= {fmt(v_bound, 3)} rad/s, "
        f"|q̈| <= {fmt(a_bound, 3)} rad/s²",
        f"cond(W) of the base parameters and friction over a period: {measures.condition_number:.4g}",
        f"peak |tau| {fmt(check.peak, 2)} N·m at t = {fmt(check.peak_time, 3)} s",
        check.verdict(),
    ]
    lines += [f"figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def _excitation(robot: RobotModel) -> tuple[Trajectory, str]:
    """The robot's excitation and where it came from (stored, or optimised now)."""
    from twolink_pin.identification.excitation import _STORED, _is_catalog_robot, excitation_trajectory

    stored = robot.name in _STORED and robot.payload == 0 and _is_catalog_robot(robot)
    if not stored:
        print(
            f"twolink-pin: optimising an excitation for {robot.name} (none is stored): this can take minutes; "
            "save one with twolink-pin excite --out FILE and pass --trajectory FILE",
            file=sys.stderr,
            flush=True,
        )
    return excitation_trajectory(robot), "stored excitation" if stored else "excitation optimised now"


def cmd_identify(args: argparse.Namespace) -> int:
    from twolink_pin.files import write_json
    from twolink_pin.identification import (
        IdentificationOptions,
        ZeroPhaseFilter,
        add_noise,
        identification_document,
        identify,
        read_log,
        simulate_log,
        write_log,
    )
    from twolink_pin.identification.simulated import DEFAULT_DT

    robot = _robot(args)
    if args.data:
        given = [
            name for name, value in (("--duration", args.duration), ("--dt", args.dt)) if value is not None
        ]
        if given:
            raise InvalidParameterError(
                given[0], getattr(args, given[0][2:]), "no value with --data (it shapes a simulated run only)"
            )
        log = read_log(args.data, robot.nv)
        reference = f"data {args.data}"
        if args.reference:
            from dataclasses import replace

            from twolink_pin.trajectory import read_trajectory_file

            log = replace(log, reference=read_trajectory_file(args.reference, robot))
            reference += f", reference {args.reference}"
    else:
        from twolink_pin.trajectory import read_trajectory_file

        if args.reference:
            raise InvalidParameterError(
                "--reference", args.reference, "a file only with --data (a simulated run knows its reference)"
            )
        if args.trajectory:
            trajectory: Trajectory = read_trajectory_file(args.trajectory, robot)
            reference = f"trajectory {args.trajectory}"
        else:
            trajectory, reference = _excitation(robot)
        log = simulate_log(
            robot, trajectory, duration=args.duration, dt=DEFAULT_DT if args.dt is None else args.dt
        )
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
    lines += [f"  figure {f}" for f in figures]
    if args.save:
        lines.append(f"  parameters saved to {args.save} (use with --p0 / --model)")
    if args.save_data:
        lines.append(f"  log saved to {args.save_data}")
    emit(args, document, "\n".join(lines))
    return 0


def cmd_excite(args: argparse.Namespace) -> int:
    from twolink_pin.identification import ExcitationDesign, ExcitationLimits, optimise_excitation
    from twolink_pin.identification.measures import averaged_adaptation, excitation_measures
    from twolink_pin.trajectory import default_trajectory, write_trajectory_file

    robot = _robot(args)
    if Path(args.out).suffix.lower() not in (".json", ".toml"):
        raise InvalidParameterError("--out", args.out, "a trajectory file name ending in .json or .toml")
    limits = ExcitationLimits(
        position_margin=args.position_margin,
        velocity_fraction=args.velocity_fraction,
        acceleration=args.acceleration,
        torque_fraction=args.torque_fraction,
    )
    design = ExcitationDesign(
        harmonics=args.harmonics,
        period=args.period,
        criterion=args.criterion,
        samples=args.samples,
        starts=args.starts,
        max_iterations=args.max_iterations,
        seed=args.seed,
        limits=limits,
    )
    from twolink_pin.identification.excitation_check import check_excitation_work, excitation_problem

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
        "message": excitation.message,
        "design": {"harmonics": design.harmonics, "period_s": design.period, "samples": design.samples},
        "limits": excitation.limits,
        "peaks": excitation.peaks,
        "fourier": excitation.trajectory.as_dict(),
    }
    if robot.name == "twolink":
        payload["report_condition_number"] = default.condition_number
    try:
        from twolink_pin.scenario import make_scenario

        law = make_scenario("adaptive", robot).controller
        payload["adaptive_slowest_time_constant_s"] = averaged_adaptation(
            law, excitation.trajectory
        ).slowest_time_constant
        payload["default_trajectory_adaptive_slowest_time_constant_s"] = averaged_adaptation(
            law, default_trajectory(robot)
        ).slowest_time_constant
    except InvalidParameterError:  # pragma: no cover - the built-in adaptive law always applies
        pass
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
    which = "the report's trajectory" if robot.name == "twolink" else "the default trajectory"
    lines = [
        f"excitation for {robot.name} ({design.criterion}): {design.harmonics} harmonics, period {design.period:g} s "
        f"-> {written}",
        f"  optimiser: SLSQP from {design.starts} seeded starts (seed {design.seed}), {excitation.iterations} iterations, "
        f"{excitation.evaluations} evaluations, {excitation.seconds:.1f} s; {excitation.message}"
        + (
            ""
            if excitation.success
            else " (NOT converged to a feasible point: more --max-iterations or --starts)"
        ),
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
    lines += [f"  figure {f}" for f in figures]
    emit(args, payload, "\n".join(lines))
    return 0


def _result_payload(result: SimulationResult, metrics: Metrics) -> dict[str, Any]:
    return {
        "controller": result.controller,
        "robot": result.robot,
        "duration": result.duration,
        "dt": result.dt,
        "metrics": metrics.as_dict(),
        "peak_torque": np.abs(result.tau).max(axis=0).tolist(),
        "peak_command": np.abs(result.tau_command).max(axis=0).tolist(),
        "torque_limits": result.torque_limits.tolist(),
        "limit_exceeded": result.limit_exceeded.tolist(),
        "limit_exceeded_at": result.first_exceeded_at,
        "parameter_names": list(result.parameter_names),
        "p_true": None if result.p_true is None else result.p_true.tolist(),
        "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
    }


def cmd_simulate(args: argparse.Namespace) -> int:
    from twolink_pin.metrics import compute_metrics

    robot = _robot(args)
    result = _run_one(args, args.controller, robot)
    metrics = compute_metrics(result)
    payload = _result_payload(result, metrics)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.files import removed_on_failure
        from twolink_pin.plotting import save_simulation_figures

        with removed_on_failure(args.plot) as folder:
            figures = [str(p) for p in save_simulation_figures(result, folder)]
    if args.save:
        from twolink_pin.simulation.storage import save_result

        save_result(result, args.save)
    payload["figures"] = figures
    lines = [
        f"controller {result.controller} on {result.robot}: {result.duration:g} s, dt = {result.dt:g} s ({result.method})",
        f"  RMS  e {fmt(metrics.rms.e, 5)} rad   edot {fmt(metrics.rms.edot, 5)} rad/s   tau {fmt(metrics.rms.tau, 3)} N·m",
        f"  max  e {fmt(metrics.max.e, 5)} rad   edot {fmt(metrics.max.edot, 5)} rad/s   tau {fmt(metrics.max.tau, 3)} N·m",
        f"  last period max |e| ({', '.join(f'{x:.4g}' for x in metrics.final_period_max_abs_e)}) rad"
        + (
            f" (the run is shorter than one {result.reference_period:g}-s period: over the whole run)"
            if result.duration < result.reference_period
            else ""
        ),
    ]
    for j, (over, at) in enumerate(zip(result.limit_exceeded, result.first_exceeded_at)):
        if over:
            lines.append(
                f"  joint {j + 1}: commanded torque exceeded its {result.torque_limits[j]:g} N·m limit "
                f"(first at t = {at:.3f} s, by up to {result.limit_excess[j]:.3g} N·m"
                + (
                    ", clipped by the plant)"
                    if result.saturate
                    else "; not saturated: add --saturate to clip)"
                )
            )
    if not np.isfinite(result.torque_limits).any():
        lines.append("  no effort limits in the model: torques are not checked against limits")
    if result.p_hat is not None and result.p_true is not None:
        if len(result.parameter_names) <= 8:
            lines.append(f"  p_hat(end) {fmt(result.p_hat[-1])}  true {fmt(result.p_true)}")
        else:
            err = np.abs(result.p_hat[-1] - result.p_true)
            lines.append(
                f"  {len(result.parameter_names)} estimates; max |p_hat − p| at the end {err.max():.4g}"
            )
    lines += [f"  figure {f}" for f in figures]
    if args.save:
        lines.append(f"  saved {args.save}")
    emit(args, payload, "\n".join(lines))
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from twolink_pin.controllers import CONTROLLERS
    from twolink_pin.files import output_directory
    from twolink_pin.scenario import law_class
    from twolink_pin.studies.comparison import run_comparison

    robot = _robot(args)
    specs = args.controllers or [
        n for n, cls in CONTROLLERS.items() if cls.__module__.startswith("twolink_pin.controllers.")
    ]
    names = [law_class(s).name for s in specs]
    if len(set(names)) != len(names):
        raise InvalidParameterError("CONTROLLER", specs, "each law at most once")
    by_name = dict(zip(names, specs))
    args.lambda_optional = True
    reference = _trajectory(args, robot)
    with output_directory(args.out, ".twolink-pin-compare") as stage:
        bar = progress_bar(len(names), "run", "compare")

        def on_result(name: str, result: SimulationResult) -> None:
            if not args.no_plot:
                from twolink_pin.plotting import save_simulation_figures

                save_simulation_figures(
                    result, stage / "figures", prefix=name, title=law_class(by_name[name]).title
                )

        def progress(name: str, result: SimulationResult | None) -> None:
            if result is not None:
                bar.update(1)
            else:
                bar.set_postfix_str(name)

        try:
            table = run_comparison(
                lambda n: _run_one(args, by_name[n], robot, reference), names, progress, on_result
            )
        finally:
            bar.close()
        files = [Path(args.out) / p.name for p in table.write(stage)]
    payload = table.as_dict() | {"files": [str(f) for f in files]}
    emit(args, payload, table.markdown() + "\n" + "\n".join(f"wrote {f}" for f in files))
    return 0


RUN_OPTIONS = frozenset(
    {
        "--duration",
        "--dt",
        "--lambda",
        "--q0-offset",
        "--saturate",
        "--method",
        "--control-period",
        "--friction-smoothing",
        "--gain",
        "--p0",
        "--model",
    }
)
"""Options that shape a run: meaningless with ``animate --from`` (a saved run)."""


def cmd_animate(args: argparse.Namespace) -> int:
    import signal

    if args.from_file:
        typed = {token.split("=")[0] for token in args.argv if token.startswith("--")}
        ignored = sorted(typed & RUN_OPTIONS)
        if args.controller is not None or ignored:
            raise InvalidParameterError(
                "--from",
                args.from_file,
                "no CONTROLLER and no simulation option with it (it replays a saved run as it was); got "
                + ", ".join(([f"CONTROLLER {args.controller}"] if args.controller else []) + ignored),
            )
    robot = _robot(args)
    reference = _trajectory(args, robot)
    if args.from_file:
        from twolink_pin.simulation.storage import load_result

        result = load_result(args.from_file)
        if result.q.shape[1] != robot.nq:
            raise InvalidParameterError(
                "--from",
                args.from_file,
                f"a result for {robot.name} (nq = {robot.nq}); it has {result.q.shape[1]} joints",
            )
    elif args.controller is None:
        raise InvalidParameterError(
            "CONTROLLER", None, "a controller (name, file.py:Class) or --from FILE.npz"
        )
    else:
        result = _run_one(args, args.controller, robot, reference)
    from twolink_pin.kinematics import joint_positions

    via_q = getattr(reference, "via_q", None)  # a Fourier excitation has no via points
    points = None if via_q is None else joint_positions(robot, via_q)[:, -1, :]  # the end effector's
    if args.html:
        from twolink_pin.visualization import write_html

        path = write_html(
            robot, result.t, result.q, result.q_des, path=args.html, via_points=points, loop=args.loop
        )
        emit(args, {"html": str(path), "controller": result.controller}, f"animation written to {path}")
        return 0
    from twolink_pin.visualization import serve

    def _stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, _stop)  # a service manager's stop shuts down as cleanly as Ctrl-C
    with serve(
        robot,
        result.t,
        result.q,
        result.q_des,
        via_points=points,
        host=args.host,
        port=args.port,
        loop=args.loop,
        open_browser=not args.no_browser,
        quiet=True,
    ) as viewer:
        emit(
            args,
            {"url": viewer.url, "host": viewer.host, "port": viewer.port},
            f"meshcat viewer at {viewer.url}",
        )
        print("press Ctrl-C to stop", file=sys.stderr, flush=True)
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            print("stopping the viewer", file=sys.stderr)
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    from twolink_pin.report import ReportOptions, build_report

    options = ReportOptions(
        robot=args.robot,
        payload=args.payload,
        config=_config(args),
        lam=args.lam,
        saturate=args.saturate,
        friction_smoothing=_smoothing(args),
        controllers=None if args.controllers is None else tuple(args.controllers),
        workers=args.workers,
        animation=not args.no_animation,
        identification=not args.no_identification,
        trajectory=args.trajectory,
        p0=args.p0,
        model=args.model,
    )
    command = "twolink-pin " + " ".join(shlex.quote(a) for a in (args.argv or []))
    bar = progress_bar(1, "step", "report")

    def progress(what: str, done: int, total: int) -> None:
        bar.total = total
        bar.set_postfix_str(what)
        bar.update(done - bar.n)

    try:
        results = build_report(args.out, options, progress=progress, command_line=command)
    finally:
        bar.close()
    index = Path(args.out) / "index.html"
    emit(
        args,
        {"index": str(index), "total_seconds": results["total_seconds"]},
        f"report written to {index} in {results['total_seconds']:.1f} s",
    )
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from twolink_pin.studies import cluster
    from twolink_pin.studies.sweep import SweepConfig, run_sweep

    if (args.workers is not None or args.scheduler is not None) and not cluster.available():
        option = "--workers" if args.workers is not None else "--scheduler"
        print(
            f"twolink-pin: error: {option} needs Dask, which is not installed: {cluster.INSTALL_HINT}",
            file=sys.stderr,
        )
        return 1
    robot = _robot(args)
    trajectory = _trajectory(args, robot)
    config = SweepConfig(
        controller=args.controller,
        samples=args.samples,
        seed=args.seed,
        q0_spread=args.q0_spread,
        param_error=args.param_error,
        gains=tuple(args.gain),
        simulation=_config(args),
        lam=args.lam,
        saturate=args.saturate,
        friction_smoothing=_smoothing(args),
        chunk=args.chunk,
        threads=args.threads,
    )
    bars: list[Any] = []  # shown from the first runs on: its rate and ETA leave out a cluster's start

    def progress(done: int, total: int) -> None:
        if not bars:
            bars.append(progress_bar(config.samples, "run", f"sweep {config.controller}"))
        bars[0].update(done - bars[0].n)

    def notify(line: str) -> None:
        if bars:
            bars[0].write(line, file=sys.stderr)
        else:
            print(line, file=sys.stderr, flush=True)

    try:
        output = run_sweep(
            config,
            robot,
            trajectory,
            args.out,
            progress=progress,
            keep_trajectories=args.keep_trajectories,
            plot=not args.no_plot,
            scheduler=args.scheduler,
            workers=args.workers,
            timeout=args.connect_timeout,
            notify=notify,
        )
    finally:
        if bars:
            bars[0].close()
    summary = output.summary
    if args.json:
        payload = {**summary, "files": [str(f) for f in output.files], "seconds": output.seconds}
        emit(args, {**payload, "engine": output.engine, "chunk": output.chunk}, "")
        return 0
    lines = [
        f"sweep {summary['controller']} on {summary['robot']}: {summary['runs']} runs in {output.seconds:.1f} s "
        f"({summary['diverged']} diverged, {summary['limit_exceeded']} exceeded a torque limit)",
        f"  ran {'' if output.engine == 'in-process' else 'on '}{output.engine}, in chunks of {output.chunk} runs",
        f"  {'metric':28s} {'p5':>12s} {'median':>12s} {'p95':>12s}",
    ]
    for name, stat in summary["metrics"].items():
        cells = ["—" if stat[k] is None else f"{stat[k]:.5g}" for k in ("p5", "median", "p95")]
        lines.append(f"  {name:28s} {cells[0]:>12s} {cells[1]:>12s} {cells[2]:>12s}")
    lines += [f"  wrote {f}" for f in output.files]
    emit(args, {}, "\n".join(lines))
    return 0
