"""The tuner's plots (uPlot panels in Viser's GUI), redrawn after every run: the joint
errors [rad], the torques as a fraction of their limits (N·m where the model has none),
the task errors [mm, deg] of a task-space law, and the law's state (estimates,
integrators); while a long run is in flight, its joint errors and torques so far."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.tuning.runner import Finished, Partial

POINTS = 600
"""Largest number of samples drawn per curve."""
COLORS = ("#1c7ed6", "#e8590c", "#2f9e44", "#ae3ec9", "#f59f00", "#0c8599", "#c2255c", "#5c940d")
MAX_SERIES = 8
"""Largest number of curves in one panel."""


def _curves(
    t: np.ndarray, columns: np.ndarray, names: list[str]
) -> tuple[tuple[np.ndarray, ...], tuple[Any, ...]]:
    step = max(1, len(t) // POINTS)
    count = min(columns.shape[1], MAX_SERIES)
    data = (
        np.asarray(t[::step], dtype=float),
        *(np.asarray(columns[::step, j], dtype=float) for j in range(count)),
    )
    series = (
        {"label": "t [s]"},
        *(
            {"label": name, "stroke": COLORS[j % len(COLORS)], "width": 1.5}
            for j, name in enumerate(names[:count])
        ),
    )
    return data, series


Panels = dict[str, tuple[tuple[np.ndarray, ...], tuple[Any, ...]]]


def joint_panels(
    t: np.ndarray, q: np.ndarray, q_des: np.ndarray, tau: np.ndarray, limits: np.ndarray
) -> Panels:
    """The joint-error [rad] and torque panels (what a run in flight shows too)."""
    nv = q.shape[1]
    out = {"joint errors e = q − q_des [rad]": _curves(t, q - q_des, [f"e{j + 1}" for j in range(nv)])}
    limits = np.asarray(limits, dtype=float)
    if np.isfinite(limits).all():
        out["torque / limit (±1 = the URDF effort limit)"] = _curves(
            t, tau / limits, [f"τ{j + 1}/limit" for j in range(nv)]
        )
    else:
        out["torque τ [N·m] (no effort limits in the model)"] = _curves(
            t, tau, [f"τ{j + 1}" for j in range(nv)]
        )
    return out


def panels(done: Finished) -> Panels:
    """Title → (data, series) of every panel for the run ``done``."""
    result = done.result
    t = result.t
    out = joint_panels(t, result.q, result.q_des, result.tau_command, result.torque_limits)
    if done.task is not None:
        from twolink_pin.task_metrics import task_errors

        errors = task_errors(done.robot, result.q, result.q_des)
        columns = np.column_stack(
            [
                1e3 * np.linalg.norm(errors.position, axis=1),
                np.degrees(np.linalg.norm(errors.orientation, axis=1)),
            ]
        )
        out["task errors: |p − p_d| [mm], angle [deg]"] = _curves(
            t, columns, ["position [mm]", "angle [deg]"]
        )
    if result.p_hat is not None:
        names = list(result.parameter_names) or [f"p̂{j + 1}" for j in range(result.p_hat.shape[1])]
        out["law state: estimates p̂"] = _curves(t, result.p_hat, names)
    elif result.state is not None and result.state.size:
        names = list(result.state_names) or [f"z{j + 1}" for j in range(result.state.shape[1])]
        out["law state z"] = _curves(t, result.state, names)
    return out


class Plots:
    """The panels in ``server``'s GUI (created in the folder open at the first :meth:`show`)."""

    def __init__(self, server: Any) -> None:
        self._server = server
        self._handles: dict[str, Any] = {}

    def show(self, done: Finished) -> None:
        """Redraw every panel for ``done`` (a panel this run has no data for is hidden)."""
        self._draw(panels(done), hide_others=True)

    def show_partial(self, part: Partial) -> None:
        """Redraw the joint-error and torque panels for the part of a run simulated so far."""
        self._draw(joint_panels(part.t, part.q, part.q_des, part.tau_command, part.torque_limits), False)

    def _draw(self, wanted: Panels, hide_others: bool) -> None:
        if hide_others:
            for title, handle in self._handles.items():
                handle.visible = title in wanted
        for title, (data, series) in wanted.items():
            handle = self._handles.get(title)
            if handle is not None and len(handle.series) == len(series):
                handle.data = data
                handle.visible = True
                continue
            if handle is not None:
                handle.remove()
            self._handles[title] = self._server.gui.add_uplot(data, series, title=title, aspect=1.6)


__all__ = ["Plots", "joint_panels", "panels"]
