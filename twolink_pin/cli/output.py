"""What the CLI prints: text or JSON on stdout, progress on stderr, errors as one line."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from typing import Any

import numpy as np


def jsonable(obj: Any) -> Any:
    """``obj`` with numpy values as Python ones and non-finite floats (an absent torque limit
    is inf) as None, so ``json.dumps(allow_nan=False)`` accepts it."""
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    return obj


RESULT_STREAM: Any = None
"""Where :func:`emit` writes when set (the real stdout while ``--json`` sends everything
else written to ``sys.stdout`` to stderr: :mod:`twolink_pin.cli.guard`)."""


def emit(args: argparse.Namespace, payload: dict[str, Any], text: str) -> None:
    """Print ``payload`` as one JSON line with ``--json``, else ``text`` — after the command's
    files are in place (:func:`~twolink_pin.files.commit_outputs`: a summary never names a file
    that is not written).

    Raises:
        OutputError: stdout is closed (nothing can be printed), or the files cannot be put in place.
    """
    from twolink_pin.files import commit_outputs

    commit_outputs()
    stream = RESULT_STREAM if RESULT_STREAM is not None else sys.stdout
    if stream is None:
        from twolink_pin.errors import OutputError

        raise OutputError(
            "<stdout>", "is closed; nothing can be printed (reopen it or redirect it to a file)"
        )
    if getattr(args, "json", False):
        stream.write(json.dumps(jsonable(payload), allow_nan=False) + "\n")
    else:
        stream.write(text + "\n")
    stream.flush()


def fmt(values: Sequence[float] | np.ndarray, digits: int = 4) -> str:
    """``(x1, x2, ...)`` with ``digits`` decimals; inf as "none"."""
    return "(" + ", ".join("none" if not math.isfinite(x) else f"{x:.{digits}f}" for x in values) + ")"


def pose_lines(position: np.ndarray, rotation: np.ndarray, rpy: np.ndarray, indent: str) -> list[str]:
    """An end-effector pose as text: its rotation's rows and its ``rpy`` [rad], with the digits
    a via-pose file needs (``positions`` and ``rpy`` rows copy from here)."""
    rows = ", ".join("[" + ", ".join(f"{x:.9f}" for x in row) + "]" for row in rotation)
    return [
        f"{indent}position [{', '.join(f'{x:.9f}' for x in position)}] m",
        f"{indent}rotation [{rows}]",
        f"{indent}rpy      [{', '.join(f'{x:.9f}' for x in rpy)}] rad (R = Rz(yaw) Ry(pitch) Rx(roll), as via-pose files)",
    ]


def progress_bar(total: int, unit: str, desc: str, disable: bool = False) -> Any:
    """A tqdm bar on stderr (the one progress display): done, rate and ETA; shown only when
    stderr is a terminal (a log or a pipe stays clean), and not when ``disable``."""
    from tqdm import tqdm

    from twolink_pin.studies.progress import stderr_is_terminal

    return tqdm(
        total=total,
        unit=unit,
        desc=desc,
        file=sys.stderr,
        disable=disable or not stderr_is_terminal(),
        dynamic_ncols=True,
        mininterval=0.5,
    )


def limits_payload(check: Any) -> dict[str, Any]:
    """``trajectory --json``'s limit fields of a :class:`~twolink_pin.feasibility.TorqueCheck`
    (or a :class:`~twolink_pin.limits.LimitsCheck`): ``limits_check``
    (:meth:`~twolink_pin.limits.LimitsCheck.summary`) and its grid: ``instants`` and ``step``,
    the largest time between two [s] (a sampled reference's grid is even on each interval
    between its samples, :func:`~twolink_pin.limits.reference_motion`)."""
    limits_check = getattr(check, "limits_check", check)
    t = limits_check.motion.t
    return {
        "limits_check": limits_check.summary(),
        "limits_check_grid": {"instants": len(t), "step": float(np.diff(t).max()) if len(t) > 1 else 0.0},
    }


def limits_check_lines(check: Any) -> list[str]:
    """A :class:`~twolink_pin.limits.LimitsCheck` as a table: per kind and joint the peak, its
    time, the limit and the margin (``none``: the robot gives no such limit), then the
    verdict; the first line says how fine the grid was."""
    t = check.motion.t
    step = float(np.diff(t).max()) if len(t) > 1 else 0.0
    names = check.limits.joint_names
    width = max(5, *(len(n) for n in names))
    spacing = (
        f"{1e3 * step:.3g} ms apart"
        if np.ptp(np.diff(t)) <= 1e-9 * step
        else f"at most {1e3 * step:.3g} ms apart"
    )
    lines = [
        f"limits over one period, checked at {len(t)} instants {spacing} (torque by RNEA):",
        f"  {'limit':22s} {'joint':{width}s} {'peak':>11s} {'at t [s]':>9s} {'limit':>11s} {'margin':>11s}",
    ]
    failed = []
    for kind in check.kinds:
        for j, name in enumerate(names):
            limit, margin = float(kind.limit[j]), float(kind.margin[j])
            given = math.isfinite(margin)
            lines.append(
                f"  {kind.kind.name + ' [' + kind.kind.unit + ']':22s} {name:{width}s} {kind.peak[j]:11.5g} "
                f"{kind.time[j]:9.3f} {f'{limit:11.5g}' if given else 'none':>11s} "
                f"{f'{margin:11.4g}' if given else '':>11s}"
            )
            if margin < 0:
                failed.append(f"{kind.kind.name} of {name}")
    lines.append("within every limit" if check.within_limits else f"BEYOND A LIMIT: {', '.join(failed)}")
    return lines
