"""The ``twolink-pin`` argument parser: commands, options and the types that check numbers."""

from __future__ import annotations

import argparse
from typing import Any, NoReturn

from twolink_pin.cli.arguments import (
    MAX_DURATION,
    MAX_GAIN,
    MAX_OFFSET,
    MAX_TEXT,
    NUMBER,
    bounded,
    finite,
    port,
    whole,
)
from twolink_pin.cli.common_options import (
    add_robot_options,
    add_step_check_option,
    add_trajectory_option,
    run_group,
    run_option_strings,
)
from twolink_pin.cli.disturbance_options import add_disturbance_options
from twolink_pin.cli.equations_parser import add_equations_command
from twolink_pin.cli.examples_command import add_examples_command
from twolink_pin.cli.guard import DEFAULT_TIMEOUT, TUNE_TIMEOUT
from twolink_pin.cli.identify_parser import add_identification_commands
from twolink_pin.cli.optimal_parser import add_optimize_command, add_within_limits_options
from twolink_pin.cli.plant_options import add_plant_options
from twolink_pin.cli.sweep_options import add_sweep_draws, add_sweep_engine

CONTROLLER_HELP = (
    "a control law: a registered name (twolink-pin controllers lists them), path/to/file.py:ClassName "
    "or package.module:ClassName"
)


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line on stderr and exit 2, and that reads
    ``-1e-3`` as a number rather than an unknown option."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NUMBER  # argparse's own misses exponents (-1e-3)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message[: 2 * MAX_TEXT]}\n")


def add_sim_options(parser: argparse.ArgumentParser) -> None:
    """The run options every simulating command has (in its :func:`run_group`), ``--trajectory``
    and ``--timeout``."""
    add_trajectory_option(parser)
    p = run_group(parser)
    p.add_argument(
        "--duration",
        type=bounded(0.0, MAX_DURATION, low_open=True, unit="s"),
        default=30.0,
        help="simulated time [s] (default 30)",
    )
    p.add_argument(
        "--dt",
        type=bounded(0.0, 1.0, low_open=True, unit="s"),
        default=1e-3,
        help="RK4 step / output spacing [s] (default 0.001)",
    )
    p.add_argument(
        "--lambda",
        dest="lam",
        type=bounded(0.0, MAX_GAIN, low_open=True, unit="1/s"),
        default=None,
        help="λ of the laws that have one [1/s] (their default: 5)",
    )
    p.add_argument(
        "--q0-offset",
        nargs="+",
        type=bounded(-MAX_OFFSET, MAX_OFFSET, unit="rad"),
        default=None,
        metavar="RAD",
        help="q(0) − q_des(0) [rad]: one value for every joint or one per joint (default: the robot's, twolink 0.1 −0.1)",
    )
    p.add_argument("--saturate", action="store_true", help="clip torques at the URDF effort limits")
    p.add_argument(
        "--joint-stops",
        action="store_true",
        help="make each joint's URDF position range a hard stop: a joint reaching it is held at the bound and "
        "its velocity into it removed (a perfectly inelastic impact, after each RK4 step; docs/limits.md); "
        "default: a joint may pass its range, and the run says so",
    )
    p.add_argument("--method", choices=("rk4", "adaptive"), default="rk4", help="integrator (default rk4)")
    p.add_argument(
        "--control-period",
        type=bounded(0.0, MAX_DURATION, low_open=True, unit="s"),
        default=None,
        metavar="T",
        help="sample the law every T s (a multiple of --dt) and hold it; default: every RK4 stage",
    )
    add_step_check_option(parser)
    parser.add_argument(
        "--timeout",
        type=bounded(0.0, 1e7, unit="s"),
        default=DEFAULT_TIMEOUT,
        metavar="S",
        help=f"stop each simulation after S s of wall-clock time: a law that never returns (0: no bound; default {DEFAULT_TIMEOUT:g} = one day)",
    )
    p.add_argument(
        "--friction-smoothing",
        type=bounded(0.0, 1e3, unit="rad/s"),
        default=None,
        metavar="EPS",
        help="ε [rad/s] of tanh(v/ε) for Coulomb friction (default: exact sgn with rk4, 1e-3 with adaptive)",
    )
    p.add_argument(
        "--plant-friction",
        choices=("law", "on", "off"),
        default="law",
        help="the robot's friction in the plant: of the laws that estimate friction (law, default), of every "
        "law (on), of none (off)",
    )
    add_plant_options(parser)


def add_gain_option(p: argparse.ArgumentParser) -> None:
    run_group(p).add_argument(
        "--gain",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a gain of the law: one value for all joints or comma-separated per joint, e.g. kp=200 or kd=30,40 (repeatable)",
    )


def add_law_gain_option(p: argparse.ArgumentParser) -> None:
    """``--gain LAW.NAME=VALUE`` of the commands that run several laws."""
    run_group(p).add_argument(
        "--gain",
        action="append",
        default=[],
        metavar="LAW.NAME=VALUE",
        help="set a gain of one law: one value for all joints or comma-separated per joint, e.g. pd.kp=200 or "
        "computed-torque.kd=30,40 (repeatable)",
    )


def add_identified_options(p: argparse.ArgumentParser, several: bool = False) -> None:
    """``--p0 FILE`` / ``--model FILE``: a parameter file of ``twolink-pin identify --save``."""
    laws = "the laws that estimate parameters (others run as usual)" if several else "a law that estimates"
    group = run_group(p).add_mutually_exclusive_group()
    group.add_argument(
        "--p0",
        metavar="FILE",
        default=None,
        help=f"start the estimates of {laws} at the identified parameters of FILE (twolink-pin identify --save)",
    )
    group.add_argument(
        "--model",
        metavar="FILE",
        default=None,
        help="the law's model believes the parameters of FILE: identified (identify --save P.json) or a "
        "URDF's inertias (the plant stays the robot's; adaptive laws: p̂(0) = initial_estimate × them; "
        "friction-estimating laws: their friction too)",
    )


def build_parser() -> argparse.ArgumentParser:
    """The ``twolink-pin`` argument parser: each family of commands added by its own function."""
    from twolink_pin.cli import commands as c

    parser = Parser(
        prog="twolink-pin",
        description="Kinematics, dynamics and tracking control of robot arms on Pinocchio.",
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        help="print the traceback of a law that raised or of an internal error (as TWOLINK_PIN_DEBUG=1)",
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    _add_model_commands(sub, c)
    _add_run_commands(sub, c)
    _add_sweep_command(sub, c)
    add_identification_commands(sub, c)
    add_equations_command(sub, c)
    add_examples_command(sub)
    return parser


def _add_model_commands(sub: Any, c: Any) -> None:
    """The commands about the model alone: ``info``, ``robots``, ``controllers``, ``fk``, ``ik``, ``trajectory``."""
    p = sub.add_parser("info", help="model summary: sizes, link lengths, torque limits, parameters")
    p.add_argument("--write-urdf", metavar="FILE", help="also write the payload variant as a URDF file")
    p.add_argument(
        "--friction",
        action="store_true",
        help="append viscous and Coulomb friction per joint to the base parameters",
    )
    add_robot_options(p)
    p.set_defaults(func=c.cmd_info)

    p = sub.add_parser("robots", help="the named robots: nq, nv, gravity, effort limits")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=c.cmd_robots)

    p = sub.add_parser("controllers", help="the registered control laws, their gains and units")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=c.cmd_controllers)

    p = sub.add_parser(
        "fk", help="forward kinematics: end-effector position [m] from q [rad] (one angle per joint)"
    )
    p.add_argument("q", nargs="+", type=finite, metavar="Q", help="joint angles [rad], one per joint")
    add_robot_options(p)
    p.set_defaults(func=c.cmd_fk)

    p = sub.add_parser(
        "ik",
        help="inverse kinematics: both elbow branches of a planar 2R arm for (x, y), or a damped "
        "least-squares solution from the robot's home for (x, y[, z]) [m]",
    )
    p.add_argument("x", type=finite, help="x [m]")
    p.add_argument("y", type=finite, help="y [m]")
    p.add_argument("z", type=finite, nargs="?", default=None, help="z [m] (arms that are not planar 2R)")
    p.add_argument(
        "--seed",
        nargs="+",
        type=finite,
        default=None,
        metavar="RAD",
        help="IK seed, nv angles [rad] (default: home)",
    )
    add_robot_options(p)
    p.set_defaults(func=c.cmd_ik)

    p = sub.add_parser(
        "trajectory", help="the robot's reference trajectory, its coefficients and the torque check"
    )
    p.add_argument("--plot", metavar="DIR", help="write the trajectory's figures as PNG into DIR")
    p.add_argument(
        "--save",
        metavar="FILE",
        help="write the reference as a trajectory file (.json or .toml) that --trajectory and --reference read",
    )
    add_trajectory_option(p)
    add_within_limits_options(p, retime=True)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_trajectory)
    add_optimize_command(sub, c)


def _add_run_commands(sub: Any, c: Any) -> None:
    """The commands that run laws: ``simulate``, ``compare``, ``animate``, ``tune``, ``report``."""
    for add in (_add_simulate, _add_compare, _add_animate, _add_tune, _add_report):
        add(sub, c)


def _add_simulate(sub: Any, c: Any) -> None:
    """``simulate``: one law's run, its figures and saved result."""
    p = sub.add_parser("simulate", help="closed-loop simulation of one control law")
    p.add_argument("controller", metavar="CONTROLLER", help=CONTROLLER_HELP)
    add_sim_options(p)
    add_gain_option(p)
    add_identified_options(p)
    p.add_argument("--plot", metavar="DIR", help="write the run's figures into DIR")
    p.add_argument("--save", metavar="FILE.npz", help="save the result (for animate --from)")
    add_disturbance_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_simulate)


def _add_compare(sub: Any, c: Any) -> None:
    """``compare``: several laws on one robot, their table and figures."""
    p = sub.add_parser(
        "compare", help="several laws on one robot: the comparison table (md, csv, json) and figures"
    )
    p.add_argument(
        "controllers",
        nargs="*",
        metavar="CONTROLLER",
        help=f"{CONTROLLER_HELP} (default: every built-in law)",
    )
    add_sim_options(p)
    add_identified_options(p, several=True)
    add_law_gain_option(p)
    p.add_argument(
        "--out", default="out/compare", metavar="DIR", help="output directory (default out/compare)"
    )
    p.add_argument("--no-plot", action="store_true", help="skip the figures")
    add_disturbance_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_compare)


def _add_animate(sub: Any, c: Any) -> None:
    """``animate``: a run (new or saved) in meshcat, served or as one HTML file."""
    p = sub.add_parser("animate", help="the tracked motion in meshcat: live in the browser, or one HTML file")
    p.add_argument("controller", nargs="?", metavar="CONTROLLER", help=CONTROLLER_HELP)
    add_sim_options(p)
    add_gain_option(p)
    add_identified_options(p)
    p.add_argument(
        "--from", dest="from_file", metavar="FILE.npz", help="animate a saved result (simulate --save)"
    )
    p.add_argument(
        "--html", metavar="FILE", help="write one self-contained HTML animation instead of serving"
    )
    p.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)"
    )
    p.add_argument("--port", type=port, default=None, help="port of the viewer (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument("--loop", action="store_true", help="repeat the motion")
    add_disturbance_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_animate, run_options=run_option_strings(p))


def _set_help(parser: argparse.ArgumentParser, dest: str, text: str) -> None:
    """Give the option ``dest`` of ``parser`` its own help (a default that differs by command)."""
    for action in parser._actions:  # argparse has no public way to reach an added option
        if action.dest == dest:
            action.help = text


def _add_tune(sub: Any, c: Any) -> None:
    """``tune``: a law's gains live in the browser."""
    p = sub.add_parser(
        "tune",
        help="tune a law live in the browser: move a gain, the run is simulated again and shown",
        description="Serve a page (Viser) with the law's gains as sliders and the run's settings: each change "
        "re-simulates the run in the background (the newest change wins) and shows the arm, the plots, the "
        "metrics beside the previous run and the defaults, and the `twolink-pin simulate` line that reproduces "
        "it. The page saves the run (.npz) and its animation (.html) inside the folder tune runs in, and "
        "offers them as downloads. Ctrl-C stops it.",
    )
    p.add_argument("controller", metavar="CONTROLLER", help=CONTROLLER_HELP)
    add_sim_options(p)
    p.set_defaults(duration=None, timeout=TUNE_TIMEOUT)  # a few periods; a stuck run is left behind
    _set_help(p, "duration", "simulated time [s] (default: 3 periods of the reference, 12 s on the twolink)")
    _set_help(
        p,
        "timeout",
        f"a run that simulates no block of 128 steps for S s of wall-clock time (a law that never returns) is left "
        f"behind and shown as failed (0: no bound; default {TUNE_TIMEOUT:g}); a run superseded by a change is left "
        "behind if it has not stopped 2 s after the change",
    )
    add_gain_option(p)
    add_identified_options(p)
    p.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine only)"
    )
    p.add_argument("--port", type=port, default=None, help="port of the page (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser")
    p.add_argument(
        "--watch",
        action="store_true",
        help="reload a law file (file.py:Class) when it is saved and run again",
    )
    add_disturbance_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_tune)


def _add_report(sub: Any, c: Any) -> None:
    """``report``: the whole pipeline as one offline HTML page."""
    p = sub.add_parser("report", help="the whole pipeline as one offline HTML page (index.html) in DIR")
    p.add_argument("--out", default="out", metavar="DIR", help="output directory (default out)")
    add_sim_options(p)
    add_law_gain_option(p)
    add_identified_options(p, several=True)
    p.add_argument(
        "--controller",
        dest="controllers",
        action="append",
        default=None,
        metavar="CONTROLLER",
        help="a law to run (repeatable; default: the report's five on the twolink, every built-in law elsewhere)",
    )
    p.add_argument(
        "--workers",
        type=whole(1, 64),
        default=None,
        help="processes for the runs and figures (1 to 64; default: the cores this process may use)",
    )
    p.add_argument("--no-animation", action="store_true", help="skip the 3-D animation")
    p.add_argument(
        "--no-identification",
        action="store_true",
        help="skip the twolink's identification section (beside Fig. 27; about a third of the report's CPU time)",
    )
    p.add_argument(
        "--no-limits-section", action="store_true", help="skip the section 'The reference within the limits'"
    )
    p.add_argument(
        "--no-sim-to-sim",
        action="store_true",
        help="skip the section 'Sim-to-sim': each law on Pinocchio and on MuJoCo with the arm's effects (docs/mujoco.md)",
    )
    p.add_argument(
        "--sim-to-sim-all",
        action="store_true",
        help="in the section 'Sim-to-sim', every law with MuJoCo's no-effect check and each of the arm's "
        "effects alone too (default: the first law; every law runs on Pinocchio and with every effect)",
    )
    add_robot_options(p)
    add_disturbance_options(p)
    p.set_defaults(func=c.cmd_report)


def _add_sweep_command(sub: Any, c: Any) -> None:
    """``sweep``: the Monte Carlo study."""
    p = sub.add_parser(
        "sweep", help="Monte Carlo study of one law on the batch engine: table, summary, histograms"
    )
    p.add_argument("controller", metavar="CONTROLLER", help=CONTROLLER_HELP)
    add_sweep_draws(p)
    p.add_argument("--out", default="out/sweep", metavar="DIR", help="output directory (default out/sweep)")
    add_disturbance_options(p)
    add_sweep_engine(p)
    p.add_argument(
        "--keep-trajectories", action="store_true", help="also write every run's q, q̇, τ (large) as .npz"
    )
    p.add_argument("--no-plot", action="store_true", help="skip distributions.png")
    add_sim_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_sweep)
