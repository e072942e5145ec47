"""The motion to show: the caller's arrays checked, then resampled to animation frames.

:func:`prepare_motion` is the one entry point; every check names the offending entry and the
valid range (:class:`~twolink_pin.errors.InvalidParameterError`). Times [s], joint
angles [rad], positions [m].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from twolink_pin.contact.scene import Scene
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel


@dataclass(frozen=True)
class Motion:
    """A validated motion, resampled to the animation's frames."""

    frames: np.ndarray
    """Frame numbers, shape (F,): frame ``k`` is shown at ``k / fps`` s of animation time."""
    fps: float
    """Frames per second of motion time [1/s]."""
    q: np.ndarray
    """Joint angles at the frames [rad], shape (F, nq)."""
    q_des: np.ndarray | None
    """Desired joint angles at the frames [rad], shape (F, nq), or ``None``."""
    via_points: np.ndarray | None
    """End-effector via points [m], shape (M, 3) (z = 0 when given as (x, y)), or ``None``."""
    wrench: np.ndarray | None = None
    """Force on :attr:`wrench_frame` at the frames [N], world axes, shape (F, 3) (held from
    each sample time to the next), or ``None``."""
    wrench_frame: str | None = None
    """The frame the force acts on (None: the end effector)."""
    desired_poses: np.ndarray | None = None
    """Desired pose of the end effector at the frames (world), shape (F, 4, 4), or ``None``."""
    surfaces: Scene | None = None
    """The surfaces the arm may touch (:class:`~twolink_pin.contact.Scene`), drawn still; or ``None``."""


def _finite_array(name: str, value: npt.ArrayLike, unit: str) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError(name, value, f"an array of numbers {unit}") from exc
    bad = np.argwhere(~np.isfinite(array))
    if len(bad):
        index = tuple(int(i) for i in bad[0])
        label = f"{name}[{', '.join(map(str, index))}]" if index else name
        raise InvalidParameterError(label, float(array[index]), f"finite values {unit}")
    return array


def _check_times(t: npt.ArrayLike) -> np.ndarray:
    t_arr = _finite_array("t", t, "[s]")
    if t_arr.ndim != 1 or len(t_arr) < 2:
        raise InvalidParameterError("t.shape", t_arr.shape, "(N,) with N >= 2 sample times [s]")
    steps = np.diff(t_arr)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0)) + 1
        raise InvalidParameterError(
            f"t[{i}]",
            float(t_arr[i]),
            f"a time > t[{i - 1}] = {t_arr[i - 1]:g} s (strictly increasing times)",
        )
    return t_arr


def _check_q(name: str, q: npt.ArrayLike, n: int, nq: int) -> np.ndarray:
    q_arr = _finite_array(name, q, "[rad]")
    if q_arr.shape != (n, nq):
        raise InvalidParameterError(f"{name}.shape", q_arr.shape, f"({n}, {nq}) = (len(t), robot.nq)")
    return q_arr


def _check_fps(fps: float) -> float:
    if not (isinstance(fps, (int, float)) and not isinstance(fps, bool) and math.isfinite(fps) and fps > 0):
        raise InvalidParameterError("fps", fps, "a finite frame rate > 0 [1/s]")
    return float(fps)


def _check_via(via_points: npt.ArrayLike | None) -> np.ndarray | None:
    """Via points as (M, 3) [m]: two columns are ``(x, y)`` with z = 0."""
    if via_points is None:
        return None
    points = _finite_array("via_points", via_points, "[m]")
    if points.ndim != 2 or points.shape[1] not in (2, 3) or len(points) == 0:
        raise InvalidParameterError(
            "via_points.shape", points.shape, "(M, 2) or (M, 3) with M >= 1: end-effector positions [m]"
        )
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    return points


def _frame_numbers(t: np.ndarray, fps: float) -> np.ndarray:
    """Frames ``0, 1, 2, …`` every ``1/fps`` s from ``t[0]``, plus a last one at ``t[-1]``."""
    span = float(t[-1] - t[0]) * fps
    whole = math.floor(span + 1e-9)
    frames = np.arange(whole + 1, dtype=float)
    if span - whole > 1e-6:
        frames = np.append(frames, span)
    return frames


def _resample(t: np.ndarray, q: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Linear interpolation of every column of ``q`` (shape (N, nq)) at ``times``."""
    return np.column_stack([np.interp(times, t, q[:, j]) for j in range(q.shape[1])])


def _held(t: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """``values`` (shape (N, …)) at ``times``, each sample held until the next one."""
    return values[
        np.clip(np.searchsorted(t, times + 1e-9 * max(1.0, abs(float(t[-1]))), side="right") - 1, 0, None)
    ]


def _check_wrench(wrench: npt.ArrayLike | None, n: int) -> np.ndarray | None:
    """The force columns [N] of a wrench per sample, shape (n, 3) from (n, 3) or (n, 6)."""
    if wrench is None:
        return None
    array = _finite_array("wrench", wrench, "[N, N·m]")
    if array.ndim != 2 or array.shape[0] != n or array.shape[1] not in (3, 6):
        raise InvalidParameterError(
            "wrench.shape", array.shape, f"({n}, 3) or ({n}, 6) = (len(t), force [N] (and moment [N·m]))"
        )
    return array[:, :3]


def _check_desired(
    robot: RobotModel, desired_frame: bool | npt.ArrayLike, q_des: np.ndarray | None, n: int
) -> np.ndarray | None:
    """The desired poses per sample (shape (n, 4, 4)): the caller's, or FK of ``q_des`` (True)."""
    if desired_frame is False or desired_frame is None:
        return None
    if desired_frame is True:
        if q_des is None:
            raise InvalidParameterError(
                "desired_frame", True, "q_des (the triad is the FK of q_des) or poses"
            )
        return None  # from q_des at the frames (the scene computes it)
    poses = _finite_array("desired_frame", desired_frame, "[m]")
    if poses.shape != (n, 4, 4):
        raise InvalidParameterError(
            "desired_frame.shape", poses.shape, f"({n}, 4, 4): a homogeneous pose per sample, or True"
        )
    return poses


def prepare_motion(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None,
    via_points: npt.ArrayLike | None,
    fps: float,
    *,
    wrench: npt.ArrayLike | None = None,
    wrench_frame: str | None = None,
    desired_frame: bool | npt.ArrayLike = False,
    surfaces: Scene | None = None,
) -> Motion:
    """Check the caller's arrays against ``robot`` and resample them at ``fps`` [1/s].

    ``wrench`` (per sample, shape (N, 3) or (N, 6) [N, N·m]) and ``desired_frame`` (poses
    per sample, shape (N, 4, 4), or True: the FK of ``q_des``) are held from each sample
    to the next: a force that starts at a sample is drawn from that sample's frame on;
    ``surfaces`` (a :class:`~twolink_pin.contact.Scene`) are drawn as they are.

    Raises:
        InvalidParameterError: a shape mismatch, a non-finite value, times not strictly
            increasing, ``fps <= 0`` or via points not (M, 2) / (M, 3).
    """
    t_arr = _check_times(t)
    q_arr = _check_q("q", q, len(t_arr), robot.nq)
    q_des_arr = None if q_des is None else _check_q("q_des", q_des, len(t_arr), robot.nq)
    fps = _check_fps(fps)
    via = _check_via(via_points)
    frames = _frame_numbers(t_arr, fps)
    times = t_arr[0] + frames / fps
    times[-1] = min(times[-1], t_arr[-1])  # rounding
    forces = _check_wrench(wrench, len(t_arr))
    poses = _check_desired(robot, desired_frame, q_des_arr, len(t_arr))
    q_des_frames = None if q_des_arr is None else _resample(t_arr, q_des_arr, times)
    desired: np.ndarray | None = None
    if desired_frame is True and q_des_frames is not None:
        from twolink_pin.visualization.overlays import frame_poses

        desired = frame_poses(robot, q_des_frames, int(robot.ee_frame_id))
    elif poses is not None:
        desired = _held(t_arr, poses, times)
    return Motion(
        frames=frames,
        fps=fps,
        q=_resample(t_arr, q_arr, times),
        q_des=q_des_frames,
        via_points=via,
        wrench=None if forces is None else _held(t_arr, forces, times),
        wrench_frame=wrench_frame,
        desired_poses=desired,
        surfaces=_check_surfaces(surfaces),
    )


def _check_surfaces(surfaces: Scene | None) -> Scene | None:
    if surfaces is not None and not isinstance(surfaces, Scene):
        raise InvalidParameterError(
            "surfaces", type(surfaces).__name__, "a twolink_pin.contact.Scene or None"
        )
    return surfaces
