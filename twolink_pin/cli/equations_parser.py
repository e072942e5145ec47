"""The ``equations`` command's options (split from :mod:`.parser`, which calls
:func:`add_equations_command` from :func:`~.parser.build_parser`)."""

from __future__ import annotations

from typing import Any

from twolink_pin.cli.arguments import bounded, whole
from twolink_pin.cli.common_options import add_robot_options

EQUATIONS_TIMEOUT = 600.0
"""``equations``' default ``--timeout`` [s]: a 6-joint arm (the largest it derives) takes about
a minute on a quiet machine (docs/equations.md)."""


def add_equations_command(sub: Any, c: Any) -> None:
    """``equations``."""
    from twolink_pin.symbolic.support import MAX_JOINTS

    p = sub.add_parser(
        "equations",
        help="the equations of motion in closed form, derived from the URDF with SymPy: M(q), C(q, q̇) "
        "(Christoffel), g(q) and the regressor Y(q, q̇, q̈) in the base parameters",
    )
    p.add_argument(
        "--joints",
        type=whole(1, 1000),
        default=None,
        metavar="N",
        help=f"derive for the first N moving joints, the others held at 0 (an arm of more than {MAX_JOINTS} "
        "joints is refused; default all)",
    )
    p.add_argument("--latex", metavar="FILE", help="also write the equations as a LaTeX document (amsmath)")
    p.add_argument(
        "--python",
        metavar="FILE",
        help="also write a standalone numpy module: M(q), C(q, v), g(q), Y(q, v, a) and p_base, with "
        "Y(q, v, a) @ p_base the inverse dynamics (no twolink-pin needed to use it)",
    )
    p.add_argument(
        "--no-cache",
        action="store_true",
        help="derive afresh, neither reading nor keeping the cache ($TWOLINK_PIN_CACHE, else "
        "~/.cache/twolink-pin/equations)",
    )
    p.add_argument(
        "--timeout",
        type=bounded(0.0, 1e7, unit="s"),
        default=EQUATIONS_TIMEOUT,
        metavar="S",
        help=f"stop the derivation after S s of wall-clock time, exit status 2 (0: no bound; default "
        f"{EQUATIONS_TIMEOUT:g})",
    )
    add_robot_options(p)
    p.set_defaults(func=c.cmd_equations)
