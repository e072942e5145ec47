"""The ``identify`` and ``excite`` commands' options (split from :mod:`.parser`, which calls
:func:`add_identification_commands` from :func:`~.parser.build_parser`)."""

from __future__ import annotations

from typing import Any

from twolink_pin.cli.arguments import bounded, whole
from twolink_pin.cli.common_options import add_robot_options, add_trajectory_option


def add_identification_commands(sub: Any, c: Any) -> None:
    """``identify`` and ``excite``."""
    p = sub.add_parser(
        "identify",
        help="identify the base parameters and joint friction from a run: simulated along the robot's "
        "excitation (or --trajectory FILE), or a log of yours (--data FILE)",
    )
    _identify_data_options(p)
    _identify_run_options(p)
    _identify_fit_options(p)
    _identify_output_options(p)
    add_robot_options(p)
    p.set_defaults(func=c.cmd_identify)
    _add_excite(sub, c)


def _identify_data_options(p: Any) -> None:
    """Where the run comes from (--trajectory, --data and a bag's topics) and --physical."""
    from twolink_pin.identification.data import MAX_LOG_BYTES

    source = p.add_mutually_exclusive_group()
    add_trajectory_option(source)
    source.add_argument(
        "--data",
        metavar="FILE",
        help=f"a logged run: CSV (header t, q1..qn, tau1..taun, optional v1..vn) or NPZ (t, q, tau, optional v), "
        f"up to {MAX_LOG_BYTES >> 20} MiB; or a ROS bag of sensor_msgs/JointState (a ROS 2 bag folder, .db3, "
        ".mcap, or a ROS 1 .bag)",
    )
    p.add_argument(
        "--topic",
        default=None,
        help="with a bag: the joint-state topic (default /joint_states); joints matched to the model by name",
    )
    p.add_argument(
        "--torque-topic",
        default=None,
        metavar="TOPIC",
        help="with a bag: commanded torques (JointState effort or Float64MultiArray in the model's joint order) "
        "instead of the joint states' effort",
    )
    p.add_argument(
        "--physical",
        action="store_true",
        help="physically consistent fit: every link's pseudo-inertia positive semidefinite and friction >= 0 "
        "(cvxpy + Clarabel), compared with the unconstrained fit on the validation period",
    )


def _identify_run_options(p: Any) -> None:
    """What shapes a simulated run and the noise added to any log."""
    p.add_argument(
        "--duration",
        type=bounded(0.0, 3600.0, low_open=True, unit="s"),
        default=None,
        help="simulated run [s] (default: 4 periods of the trajectory)",
    )
    p.add_argument(
        "--dt",
        type=bounded(0.0, 0.1, low_open=True, unit="s"),
        default=None,
        help="simulated run's RK4 step and log spacing [s] (default 0.0005: a 2-kHz log)",
    )
    p.add_argument(
        "--noise-q",
        type=bounded(0.0, 1.0, unit="rad"),
        default=0.0,
        metavar="RAD",
        help="add white Gaussian noise of this standard deviation to the logged q [rad]",
    )
    p.add_argument(
        "--noise-tau",
        type=bounded(0.0, 1e4, unit="N·m"),
        default=0.0,
        metavar="NM",
        help="add white Gaussian noise of this standard deviation to the logged τ [N·m]",
    )
    p.add_argument("--seed", type=whole(0, 2**63 - 1), default=0, help="seed of the noise (default 0)")
    p.add_argument(
        "--plant",
        choices=("pinocchio", "mujoco"),
        default="pinocchio",
        help="the simulator of the simulated log: Pinocchio's ABA (default) or MuJoCo (docs/mujoco.md)",
    )


def _identify_fit_options(p: Any) -> None:
    """The filter, the validation period, friction, the reference and the estimator."""
    from twolink_pin.identification.filtering import DEFAULT_CUTOFF_HZ, DEFAULT_ORDER

    p.add_argument(
        "--cutoff",
        type=bounded(0.0, 1e5, low_open=True, unit="Hz"),
        default=DEFAULT_CUTOFF_HZ,
        metavar="HZ",
        help=f"cut-off of the zero-phase Butterworth filter [Hz] (default {DEFAULT_CUTOFF_HZ:g})",
    )
    p.add_argument(
        "--order",
        type=whole(1, 8),
        default=DEFAULT_ORDER,
        help=f"Butterworth order (default {DEFAULT_ORDER})",
    )
    p.add_argument(
        "--validation",
        type=bounded(0.0, 0.9, unit=""),
        default=0.25,
        metavar="FRAC",
        help="fraction of the run, at its end, kept for validation (default 0.25)",
    )
    p.add_argument("--no-friction", action="store_true", help="identify the base parameters only")
    p.add_argument(
        "--reversal-guard",
        action="store_true",
        help="also drop samples near velocity reversals (for logs whose accelerations jump there: friction "
        "not compensated by the controller)",
    )
    p.add_argument(
        "--reference",
        metavar="FILE",
        help="with --data: the trajectory file the arm tracked (time as in the log); its regressor is the "
        "instrument of an instrumental-variables estimate, free of the bias position noise causes",
    )
    p.add_argument(
        "--no-instruments",
        action="store_true",
        help="least squares even when the reference is known (a simulated run's excitation, or --reference)",
    )
    p.add_argument("--ols", action="store_true", help="ordinary least squares (default: Gautier's weighted)")


def _identify_output_options(p: Any) -> None:
    """Figures, saved parameters, the log used and the URDF out."""
    p.add_argument("--plot", metavar="DIR", help="write the figures (validation torques, estimates) into DIR")
    p.add_argument("--save", metavar="FILE.json", help="write the identified parameters (for --p0 / --model)")
    p.add_argument("--save-data", metavar="FILE", help="write the log used (.csv or .npz, after any noise)")
    p.add_argument(
        "--write-urdf",
        metavar="OUT.urdf",
        help="write the robot's URDF with the identified inertias and friction (<dynamics damping friction>); "
        "the estimates must be physically consistent (--physical makes them so)",
    )


def _add_excite(sub: Any, c: Any) -> None:
    """``excite``."""
    p = sub.add_parser(
        "excite",
        help="an optimised excitation: a Fourier-series trajectory of minimal condition number (or fastest "
        "adaptation) within the joint, velocity, acceleration and torque limits",
    )
    p.add_argument("--out", required=True, metavar="FILE", help="trajectory file to write (.json or .toml)")
    p.add_argument(
        "--criterion",
        choices=("condition", "adaptation"),
        default="condition",
        help="minimise cond(W) of the base parameters and friction (default), or maximise the slowest "
        "averaged adaptation rate of the robot's adaptive law",
    )
    p.add_argument("--harmonics", type=whole(1, 20), default=5, help="harmonics per joint (default 5)")
    p.add_argument(
        "--period",
        type=bounded(1e-3, 3600.0, unit="s"),  # the Fourier trajectory's shortest period
        default=10.0,
        help="period [s]: the base frequency is 1/period (default 10)",
    )
    p.add_argument(
        "--samples",
        type=whole(10, 100_000),
        default=100,
        help="instants per period of the criterion (default 100)",
    )
    p.add_argument(
        "--starts", type=whole(1, 50), default=3, help="random starts of the optimiser (default 3)"
    )
    p.add_argument(
        "--max-iterations",
        type=whole(1, 100_000),
        default=200,
        help="SLSQP iterations per start (default 200)",
    )
    p.add_argument("--seed", type=whole(0, 2**63 - 1), default=0, help="seed of the starts (default 0)")
    p.add_argument(
        "--velocity-fraction",
        type=bounded(0.0, 1.0, low_open=True, unit=""),
        default=0.5,
        metavar="F",
        help="|q̇| within F × the URDF velocity limit (default 0.5)",
    )
    p.add_argument(
        "--acceleration",
        type=bounded(0.0, 1e4, low_open=True, unit="rad/s²"),
        default=10.0,
        metavar="A",
        help="|q̈| within A [rad/s²] (default 10; URDFs give no acceleration limit)",
    )
    p.add_argument(
        "--torque-fraction",
        type=bounded(0.0, 1.0, low_open=True, unit=""),
        default=0.8,
        metavar="F",
        help="|τ| within F × the URDF effort limit (default 0.8)",
    )
    p.add_argument(
        "--position-margin",
        type=bounded(0.0, 0.49, unit=""),
        default=0.05,
        metavar="F",
        help="keep F of each joint's range free at each end (default 0.05)",
    )
    p.add_argument("--plot", metavar="DIR", help="write the excitation's figure into DIR")
    add_robot_options(p)
    p.set_defaults(func=c.cmd_excite)
