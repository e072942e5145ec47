"""``twolink-pin``: the command-line shell over the library.

Every command prints a readable summary, or JSON with ``--json``. Bad input gives one
line on stderr and exit status 2; a failed run (diverged simulation) exit status 1.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, NoReturn

import numpy as np

from twolink_pin.errors import InvalidParameterError, SimulationDivergedError, TwolinkPinError

if TYPE_CHECKING:  # the commands import the library lazily, to keep `--help` fast
    from twolink_pin.metrics import Metrics
    from twolink_pin.model import RobotModel
    from twolink_pin.simulation import SimulationResult


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line on stderr and exit 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def _positive(text: str) -> float:
    value = _finite(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def _non_negative(text: str) -> float:
    value = _finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return value


def _jsonable(obj: Any) -> Any:
    """``obj`` with non-finite floats (an absent torque limit is inf) as None."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    return obj


def _emit(args: argparse.Namespace, payload: dict[str, Any], text: str) -> None:
    if args.json:
        print(json.dumps(_jsonable(payload), allow_nan=False))
    else:
        print(text)


def _fmt(values: Sequence[float] | np.ndarray, digits: int = 4) -> str:
    return "(" + ", ".join(f"{x:.{digits}f}" for x in values) + ")"


def _robot(args: argparse.Namespace) -> RobotModel:
    from twolink_pin.model import load_robot

    return load_robot(getattr(args, "urdf", None), payload=getattr(args, "payload", 0.0))


# -- commands ---------------------------------------------------------------------------


def cmd_info(args: argparse.Namespace) -> int:
    robot = _robot(args)
    payload = {
        "nq": robot.nq,
        "nv": robot.nv,
        "link_lengths": robot.link_lengths.tolist(),
        "torque_limits": robot.torque_limits.tolist(),
        "p": robot.p.tolist(),
    }
    names = robot.parameter_map.names
    p_text = (
        ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, robot.p))
        if len(names) <= 6
        else f"{len(names)} values"
    )
    text = "\n".join(
        [
            f"robot      {robot.model.name} ({robot.urdf_path})",
            f"joints     nq = {robot.nq}, nv = {robot.nv}; end effector '{robot.ee_frame}'",
            f"links      {_fmt(robot.link_lengths, 3)} m",
            f"limits     {_fmt(robot.torque_limits, 1)} N·m",
            f"payload    {robot.payload:g} kg",
            f"parameters {p_text}",
        ]
    )
    if args.write_urdf:
        from twolink_pin.model.payload import write_payload_urdf

        if robot.payload <= 0:
            raise InvalidParameterError(
                "--payload", robot.payload, "a mass > 0 kg to write a payload variant"
            )
        written = write_payload_urdf(robot.urdf_path, robot.payload, args.write_urdf, robot.ee_frame)
        payload["urdf_written"] = str(written)
        text += f"\nwrote   {written}"
    _emit(args, payload, text)
    return 0


def cmd_fk(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import forward_kinematics

    robot = _robot(args)
    q = np.array([args.q1, args.q2])
    xy = forward_kinematics(robot, q)
    _emit(args, {"xy": xy.tolist()}, f"end effector at {_fmt(xy)} m for q = {_fmt(q)} rad")
    return 0


def cmd_ik(args: argparse.Namespace) -> int:
    from twolink_pin.kinematics import inverse_kinematics

    robot = _robot(args)
    sols = inverse_kinematics(robot, (args.x, args.y))
    text = "\n".join(
        f"{label}: q = {_fmt(s)} rad" for label, s in zip(("elbow q2 >= 0", "elbow q2 <= 0"), sols)
    )
    _emit(args, {"solutions": sols.tolist()}, text)
    return 0


def cmd_trajectory(args: argparse.Namespace) -> int:
    from twolink_pin.feasibility import check_torques
    from twolink_pin.trajectory import ViaPoints, build_trajectory

    robot = _robot(args)
    via = ViaPoints()
    traj = build_trajectory(robot, via)
    check = check_torques(robot, traj)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.plotting import save_trajectory_figures

        figures = [str(p) for p in save_trajectory_figures(robot, traj, check, Path(args.plot))]
    payload = {
        "times": traj.times.tolist(),
        "via_xy": [list(p) for p in via.xy],
        "via_q": traj.via_q.tolist(),
        "coefficients": traj.coefficients.tolist(),
        "peak_torque": check.peak.tolist(),
        "peak_time": check.peak_time.tolist(),
        "torque_limits": check.limits.tolist(),
        "margin": check.margin.tolist(),
        "within_limits": check.within_limits,
        "figures": figures,
    }
    lines = ["via points (t [s], (x, y) [m], q [rad], branch q2 >= 0):"]
    lines += [f"  {t:4.1f}  {_fmt(xy, 3)}  {_fmt(q)}" for t, xy, q in zip(traj.times, via.xy, traj.via_q)]
    for j, c in enumerate(traj.coefficients):
        terms = " ".join(f"{x:+.5g}" for x in c)
        lines.append(f"theta{j + 1}(t) coefficients, ascending powers of t: {terms}")
    lines.append(f"peak |tau| {_fmt(check.peak, 2)} N·m at t = {_fmt(check.peak_time, 3)} s")
    lines.append(check.verdict())
    lines += [f"figure {f}" for f in figures]
    _emit(args, payload, "\n".join(lines))
    return 0


def _run_one(args: argparse.Namespace, name: str, robot: RobotModel) -> SimulationResult:
    from twolink_pin.scenarios import make_scenario
    from twolink_pin.simulation import SimulationConfig, simulate
    from twolink_pin.trajectory import build_trajectory

    config = SimulationConfig(
        duration=args.duration,
        dt=args.dt,
        method=args.method,
        q0_offset=tuple(args.q0_offset),
        control_period=args.control_period,
    )
    smoothing = args.friction_smoothing
    if smoothing is None:
        smoothing = 1e-3 if args.method == "adaptive" else 0.0
    controller, plant = make_scenario(
        name, robot, lam=args.lam, saturate=args.saturate, friction_smoothing=smoothing
    )
    return simulate(controller, plant, build_trajectory(robot), config)


def _result_payload(result: SimulationResult, metrics: Metrics, robot: RobotModel) -> dict[str, Any]:
    return {
        "controller": result.controller,
        "duration": result.duration,
        "dt": result.dt,
        "metrics": metrics.as_dict(),
        "peak_torque": np.abs(result.tau).max(axis=0).tolist(),
        "limit_exceeded": result.limit_exceeded.tolist(),
        "limit_exceeded_at": result.first_exceeded_at,
        "p_true": (result.p_true if result.p_true is not None else robot.p).tolist(),
        "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
    }


def cmd_simulate(args: argparse.Namespace) -> int:
    from twolink_pin.metrics import compute_metrics

    robot = _robot(args)
    result = _run_one(args, args.controller, robot)
    metrics = compute_metrics(result)
    payload = _result_payload(result, metrics, robot)
    figures: list[str] = []
    if args.plot:
        from twolink_pin.plotting import save_simulation_figures

        figures = [str(p) for p in save_simulation_figures(result, Path(args.plot))]
    if args.save:
        from twolink_pin.storage import save_result

        save_result(result, args.save)
    payload["figures"] = figures
    lines = [
        f"controller {result.controller}: {result.duration:g} s, dt = {result.dt:g} s ({result.method})",
        f"  RMS  e {_fmt(metrics.rms.e, 5)} rad   edot {_fmt(metrics.rms.edot, 5)} rad/s   "
        f"tau {_fmt(metrics.rms.tau, 3)} N·m",
        f"  max  e {_fmt(metrics.max.e, 5)} rad   edot {_fmt(metrics.max.edot, 5)} rad/s   "
        f"tau {_fmt(metrics.max.tau, 3)} N·m",
        f"  last period max |e| {_fmt(metrics.final_period_max_abs_e, 8)} rad",
    ]
    for j, (over, at) in enumerate(zip(result.limit_exceeded, result.first_exceeded_at)):
        if over:
            lines.append(
                f"  joint {j + 1}: commanded torque exceeded its {result.torque_limits[j]:g} N·m limit "
                f"(first at t = {at:.3f} s, by up to {result.limit_excess[j]:.2f} N·m)"
            )
    if result.p_hat is not None and result.p_true is not None:
        lines.append(f"  p_hat(end) {_fmt(result.p_hat[-1])}  true {_fmt(result.p_true)}")
    lines += [f"  figure {f}" for f in figures]
    if args.save:
        lines.append(f"  saved {args.save}")
    _emit(args, payload, "\n".join(lines))
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from twolink_pin.comparison import run_comparison

    robot = _robot(args)

    def progress(i: int, n: int, name: str, seconds: float | None) -> None:
        if seconds is None:
            print(f"[{i}/{n}] {name} ...", file=sys.stderr, flush=True)
        else:
            print(f"[{i}/{n}] {name} done in {seconds:.1f} s", file=sys.stderr, flush=True)

    runner: Callable[[str], Any] = lambda name: _run_one(args, name, robot)  # noqa: E731
    table = run_comparison(runner, Path(args.out), progress=progress, plots=True)
    _emit(args, table.as_dict(), table.markdown())
    return 0


def cmd_animate(args: argparse.Namespace) -> int:
    from twolink_pin.trajectory import REPORT_VIA_XY

    robot = _robot(args)
    if args.from_file:
        from twolink_pin.storage import load_result

        result = load_result(args.from_file)
    elif args.controller is None:
        raise InvalidParameterError("CONTROLLER", None, "a controller name, or --from FILE.npz")
    else:
        result = _run_one(args, args.controller, robot)
    via = REPORT_VIA_XY if robot.nv == 2 else None
    if args.html:
        from twolink_pin.visualization import write_html

        path = write_html(robot, result.t, result.q, result.q_des, path=args.html, via_xy=via, loop=args.loop)
        _emit(args, {"html": str(path), "controller": result.controller}, f"animation written to {path}")
        return 0
    import signal
    import threading

    from twolink_pin.visualization import serve

    def _stop(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, _stop)  # a service manager's stop shuts down as cleanly as Ctrl-C

    with serve(
        robot,
        result.t,
        result.q,
        result.q_des,
        via_xy=via,
        host=args.host,
        port=args.port,
        loop=args.loop,
        open_browser=not args.no_browser,
        quiet=True,
    ) as viewer:
        _emit(
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


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a port number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"expected a port in 0..65535, got {text!r}")
    return value


def cmd_report(args: argparse.Namespace) -> int:
    import shlex

    from twolink_pin.report import ReportOptions, build_report, terminal_progress
    from twolink_pin.simulation import SimulationConfig

    options = ReportOptions(
        urdf=args.urdf,
        payload=args.payload,
        config=SimulationConfig(
            duration=args.duration,
            dt=args.dt,
            method=args.method,
            q0_offset=tuple(args.q0_offset),
            control_period=args.control_period,
        ),
        lam=args.lam,
        workers=args.workers,
        animation=not args.no_animation,
    )
    command = "twolink-pin " + " ".join(shlex.quote(a) for a in (args.argv or []))
    results = build_report(
        args.out, options, progress=None if args.json else terminal_progress, command_line=command
    )
    index = Path(args.out) / "index.html"
    payload = {"index": str(index), "total_seconds": results["total_seconds"]}
    _emit(args, payload, f"report written to {index} in {results['total_seconds']:.1f} s")
    return 0


def _number(low: float, high: float, closed_high: bool) -> Callable[[str], float]:
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not (math.isfinite(value) and low <= value and (value <= high if closed_high else value < high)):
            bound = "]" if closed_high else ")"
            raise argparse.ArgumentTypeError(f"expected a number in [{low:g}, {high:g}{bound}, got {text!r}")
        return value

    return parse


def _gain(text: str) -> Any:
    from twolink_pin.sweep import GainRange

    try:
        return GainRange.parse(text)
    except InvalidParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _add_sweep_parser(subparsers: Any, controllers: list[str]) -> None:
    """The ``sweep`` command (``func`` is :func:`cmd_sweep`)."""
    p = subparsers.add_parser(
        "sweep", help="Monte Carlo study of one controller on the batch engine: table, summary, histograms"
    )
    p.add_argument("controller", choices=controllers)
    p.add_argument("--samples", type=_positive_int, required=True, metavar="N", help="number of runs")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0): same seed, same files")
    p.add_argument(
        "--q0-spread",
        type=_number(0.0, math.inf, False),
        default=0.0,
        metavar="RAD",
        help="initial error q0-offset ± U(RAD) per joint [rad] (default 0)",
    )
    p.add_argument(
        "--param-error",
        type=_number(0.0, 1.0, False),
        default=0.0,
        metavar="FRAC",
        help="controller's parameters p·(1 + U(±FRAC)) per parameter (default 0)",
    )
    p.add_argument(
        "--gain",
        type=_gain,
        action="append",
        default=[],
        metavar="NAME=LO:HI",
        help="draw a gain uniformly, e.g. kp=100:400, kd2=20:80, lam=1:10, model_scale=0.2:1 (repeatable)",
    )
    p.add_argument("--out", default="out/sweep", metavar="DIR", help="output directory (default out/sweep)")
    p.add_argument(
        "--threads", type=_positive_int, default=None, help="threads of the batch engine (default all cores)"
    )
    p.add_argument(
        "--chunk", type=_positive_int, default=1000, metavar="N", help="runs per batch (default 1000)"
    )
    p.add_argument(
        "--keep-trajectories", action="store_true", help="also write every run's q, q̇, τ (large) as .npz"
    )
    p.add_argument("--no-plot", action="store_true", help="skip distributions.png")
    _add_sim_options(p)
    _add_robot_options(p)
    p.set_defaults(func=cmd_sweep)


class _ProgressBar:
    """A one-line progress bar on stderr (redrawn on a terminal, every 10 % otherwise)."""

    def __init__(self, stream: IO[str] | None = None, width: int = 30) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.started = time.perf_counter()
        self.shown = -1

    def __call__(self, done: int, total: int) -> None:
        fraction = done / total if total else 1.0
        step = int(fraction * 100) if self.tty else int(fraction * 10) * 10
        if step == self.shown:
            return
        self.shown = step
        elapsed = time.perf_counter() - self.started
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else math.nan
        filled = round(self.width * fraction)
        line = (
            f"[{'#' * filled}{'.' * (self.width - filled)}] {100 * fraction:5.1f}%  {done}/{total} runs  "
            f"{elapsed:6.1f} s" + (f"  ETA {eta:5.0f} s" if math.isfinite(eta) and done < total else "")
        )
        self.stream.write(("\r" + line) if self.tty else line + "\n")
        if self.tty and done >= total:
            self.stream.write("\n")
        self.stream.flush()


def cmd_sweep(args: argparse.Namespace) -> int:
    """``twolink-pin sweep``: run the study, print its summary (text or ``--json``)."""
    from twolink_pin.simulation import SimulationConfig
    from twolink_pin.sweep import SweepConfig, run_sweep
    from twolink_pin.trajectory import build_trajectory

    robot = _robot(args)
    smoothing = getattr(args, "friction_smoothing", None)
    simulation = SimulationConfig(
        duration=args.duration,
        dt=args.dt,
        method=getattr(args, "method", "rk4"),
        q0_offset=tuple(args.q0_offset),
        control_period=getattr(args, "control_period", None),
    )
    config = SweepConfig(
        controller=args.controller,
        samples=args.samples,
        seed=args.seed,
        q0_spread=args.q0_spread,
        param_error=args.param_error,
        gains=tuple(args.gain),
        simulation=simulation,
        lam=getattr(args, "lam", None),
        saturate=getattr(args, "saturate", False),
        friction_smoothing=0.0 if smoothing is None else smoothing,
        chunk=args.chunk,
        threads=args.threads,
    )
    output = run_sweep(
        config,
        robot,
        build_trajectory(robot),
        args.out,
        progress=_ProgressBar(),
        keep_trajectories=args.keep_trajectories,
        plot=not args.no_plot,
    )
    summary = output.summary
    if getattr(args, "json", False):
        payload = {**summary, "files": [str(f) for f in output.files], "seconds": output.seconds}
        print(json.dumps(payload, allow_nan=False))
        return 0
    lines = [
        f"sweep {config.controller}: {summary['runs']} runs in {output.seconds:.1f} s "
        f"({summary['diverged']} diverged, {summary['limit_exceeded']} exceeded a torque limit)",
        f"  {'metric':28s} {'p5':>12s} {'median':>12s} {'p95':>12s}",
    ]
    for name, stat in summary["metrics"].items():
        cells = ["—" if stat[k] is None else f"{stat[k]:.5g}" for k in ("p5", "median", "p95")]
        lines.append(f"  {name:28s} {cells[0]:>12s} {cells[1]:>12s} {cells[2]:>12s}")
    lines += [f"  wrote {f}" for f in output.files]
    print("\n".join(lines))
    return 0


# -- parser -----------------------------------------------------------------------------


def _add_robot_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--urdf", help="URDF file (default: the shipped twolink)")
    p.add_argument("--payload", type=_non_negative, default=0.0, help="point mass at the end effector [kg]")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def _add_sim_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--duration", type=_positive, default=30.0, help="simulated time [s] (default 30)")
    p.add_argument("--dt", type=_positive, default=1e-3, help="RK4 step / output spacing [s] (default 0.001)")
    p.add_argument(
        "--lambda", dest="lam", type=_positive, default=None, help="λ of the Slotine–Li laws [1/s] (5)"
    )
    p.add_argument(
        "--q0-offset",
        nargs=2,
        type=_finite,
        default=(0.1, -0.1),
        metavar=("D1", "D2"),
        help="q(0) − q_des(0) [rad] (default 0.1 −0.1)",
    )
    p.add_argument("--saturate", action="store_true", help="clip torques at the URDF limits")
    p.add_argument("--method", choices=("rk4", "adaptive"), default="rk4", help="integrator (default rk4)")
    p.add_argument(
        "--control-period",
        type=_positive,
        default=None,
        metavar="T",
        help="sample the law every T s (a multiple of --dt) and hold it; default: every RK4 stage",
    )
    p.add_argument(
        "--friction-smoothing",
        type=_non_negative,
        default=None,
        help="ε [rad/s] of tanh(v/ε) for Coulomb friction (default: exact sgn with rk4, 1e-3 with adaptive)",
    )


def build_parser() -> argparse.ArgumentParser:
    """The ``twolink-pin`` argument parser."""
    from twolink_pin.controllers import CONTROLLERS

    parser = _Parser(prog="twolink-pin", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    p = sub.add_parser("info", help="model summary: sizes, link lengths, torque limits, parameters")
    p.add_argument("--write-urdf", metavar="FILE", help="also write the payload variant as a URDF file")
    _add_robot_options(p)
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("fk", help="forward kinematics: end-effector (x, y) [m] from q [rad]")
    p.add_argument("q1", type=_finite, help="joint 1 angle [rad]")
    p.add_argument("q2", type=_finite, help="joint 2 angle [rad]")
    _add_robot_options(p)
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("ik", help="inverse kinematics: both elbow branches for (x, y) [m]")
    p.add_argument("x", type=_finite)
    p.add_argument("y", type=_finite)
    _add_robot_options(p)
    p.set_defaults(func=cmd_ik)

    p = sub.add_parser("trajectory", help="the via-point trajectory, its coefficients and the torque check")
    p.add_argument("--plot", metavar="DIR", help="write Figures 3–6 as PNG into DIR")
    _add_robot_options(p)
    p.set_defaults(func=cmd_trajectory)

    p = sub.add_parser("simulate", help="closed-loop simulation of one controller")
    p.add_argument("controller", choices=list(CONTROLLERS))
    _add_sim_options(p)
    p.add_argument("--plot", metavar="DIR", help="write the controller's figures into DIR")
    p.add_argument("--save", metavar="FILE.npz", help="save the result (for animate --from)")
    _add_robot_options(p)
    p.set_defaults(func=cmd_simulate)

    p = sub.add_parser("compare", help="run all five controllers: Table 2 (md, csv, json) and figures")
    _add_sim_options(p)
    p.add_argument(
        "--out", default="out/compare", metavar="DIR", help="output directory (default out/compare)"
    )
    _add_robot_options(p)
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("animate", help="the tracked motion in meshcat: live in the browser, or one HTML file")
    p.add_argument("controller", nargs="?", choices=list(CONTROLLERS), help="controller to simulate")
    _add_sim_options(p)
    p.add_argument(
        "--from", dest="from_file", metavar="FILE.npz", help="animate a saved result (simulate --save)"
    )
    p.add_argument(
        "--html", metavar="FILE", help="write one self-contained HTML animation instead of serving"
    )
    p.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)"
    )
    p.add_argument("--port", type=_port, default=None, help="port of the viewer (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument("--loop", action="store_true", help="repeat the motion")
    _add_robot_options(p)
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("report", help="reproduce the whole course report as HTML (index.html) in DIR")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory (default out)")
    _add_sim_options(p)
    p.add_argument("--workers", type=_positive_int, default=2, help="processes for the five runs (default 2)")
    p.add_argument("--no-animation", action="store_true", help="skip the 3-D animation")
    _add_robot_options(p)
    p.set_defaults(func=cmd_report)

    _add_sweep_parser(sub, list(CONTROLLERS))
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``twolink-pin`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    try:
        return int(args.func(args))
    except SimulationDivergedError as exc:
        print(f"twolink-pin: {exc}", file=sys.stderr)
        return 1
    except (TwolinkPinError, InvalidParameterError) as exc:
        print(f"twolink-pin: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("twolink-pin: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
