"""The tuner's plots (uPlot panels in Viser's GUI), redrawn after every run: the joint
errors [rad], the torques as a fraction of their limits (N·m where the model has none),
the task errors [mm, deg] of a task-space law, and the law's state (estimates, with the
true parameters as dashed lines; integrators); while a long run is in flight, its joint
errors and torques so far.

The time axis is in seconds. Beside the latest run each panel draws, faded, the previous
run, the defaults' run and a kept run (the "keep this run" button), each resampled on the
latest run's times (none past its own end). A curve has at most :data:`POINTS` samples:
what the page is sent per run stays small whatever the run's length."""

from __future__ import annotations

import contextlib
import threading
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.tuning.runner import Finished, Partial

POINTS = 500
"""Largest number of samples drawn per curve."""
COLORS = ("#1c7ed6", "#e8590c", "#2f9e44", "#ae3ec9", "#f59f00", "#0c8599", "#c2255c", "#5c940d")
MAX_SERIES = 8
"""Largest number of curves of one run in one panel."""
STYLES: dict[str, tuple[str, float, list[int]]] = {
    "previous": ("88", 1.0, [6, 4]),
    "defaults": ("66", 1.0, [2, 3]),
}
"""How a reference run is drawn: its colour's alpha (hex), width [px], dash; a kept run is grey."""
KEPT_STROKE = "#495057"
X_SCALE = {"x": {"time": False}}
"""uPlot's x scale: numbers (seconds), not dates."""


class Curves(NamedTuple):
    """One panel's curves of one run."""

    t: np.ndarray
    """Times [s], (k,)."""
    columns: np.ndarray
    """The curves, (k, m)."""
    names: tuple[str, ...]
    """Their labels."""
    truth: np.ndarray | None = None
    """True values drawn as horizontal dashed lines (the estimates' parameters), (m,)."""


Panels = dict[str, Curves]


def joint_panels(
    t: np.ndarray, q: np.ndarray, q_des: np.ndarray, tau: np.ndarray, limits: np.ndarray
) -> Panels:
    """The joint-error [rad] and torque panels (what a run in flight shows too)."""
    nv = q.shape[1]
    out = {"joint errors e = q − q_des [rad]": Curves(t, q - q_des, tuple(f"e{j + 1}" for j in range(nv)))}
    limits = np.asarray(limits, dtype=float)
    if np.isfinite(limits).all():
        out["torque / limit (±1 = the URDF effort limit)"] = Curves(
            t, tau / limits, tuple(f"τ{j + 1}/limit" for j in range(nv))
        )
    else:
        out["torque τ [N·m] (no effort limits in the model)"] = Curves(
            t, tau, tuple(f"τ{j + 1}" for j in range(nv))
        )
    return out


def panels(done: Finished) -> Panels:
    """Title → curves of every panel for the run ``done``."""
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
        out["task errors: |p − p_d| [mm], angle [deg]"] = Curves(t, columns, ("position [mm]", "angle [deg]"))
    if result.p_hat is not None:
        names = tuple(result.parameter_names) or tuple(f"p̂{j + 1}" for j in range(result.p_hat.shape[1]))
        truth = None if result.p_true is None else np.asarray(result.p_true, dtype=float).reshape(-1)
        title = "law state: estimates p̂" + (" (dashed: the true p)" if truth is not None else "")
        out[title] = Curves(t, result.p_hat, names, truth)
    elif result.state is not None and result.state.size:
        width = result.state.shape[1]
        names = tuple(result.state_names) or tuple(f"z{j + 1}" for j in range(width))
        units = tuple(result.state_units) if len(result.state_units) == width else ("",) * width
        for unit in dict.fromkeys(units):  # one panel per unit, as the report's state figure
            picked = [j for j in range(width) if units[j] == unit]
            title = f"law state z [{unit}]" if unit else "law state z"
            out[title] = Curves(t, result.state[:, picked], tuple(names[j] for j in picked))
    return out


def _resampled(curves: Curves, t: np.ndarray, count: int) -> list[np.ndarray]:
    """``curves``' first ``count`` columns at the times ``t`` [s] (NaN past its end)."""
    end = float(curves.t[-1]) if len(curves.t) else -np.inf
    out = []
    for j in range(min(count, curves.columns.shape[1])):
        column = np.interp(t, curves.t, curves.columns[:, j])
        out.append(np.where(t <= end + 1e-12, column, np.nan))
    return out


def compose(
    latest: Curves, references: dict[str, Curves | None] | None = None
) -> tuple[tuple[np.ndarray, ...], tuple[dict[str, Any], ...]]:
    """uPlot's data and series of one panel: the latest run's curves (at most
    :data:`POINTS` samples each), its true values, then each reference run's, faded.

    Args:
        references: Name (``previous``, ``defaults`` or a kept run's) → its curves of the
            same panel (None or a different number of curves: not drawn).
    """
    step = max(1, -(-len(latest.t) // POINTS))
    t = np.asarray(latest.t[::step], dtype=float)
    count = min(latest.columns.shape[1], MAX_SERIES)
    data: list[np.ndarray] = [t, *(np.asarray(latest.columns[::step, j], dtype=float) for j in range(count))]
    series: list[dict[str, Any]] = [{"label": "t [s]"}]
    series += [
        {"label": name, "stroke": COLORS[j % len(COLORS)], "width": 1.5}
        for j, name in enumerate(latest.names[:count])
    ]
    if latest.truth is not None:
        for j in range(min(count, len(latest.truth))):
            data.append(np.full(len(t), float(latest.truth[j])))
            series.append(
                {
                    "label": f"{latest.names[j]} true",
                    "stroke": COLORS[j % len(COLORS)],
                    "width": 1.0,
                    "dash": [4, 4],
                }
            )
    for name, curves in (references or {}).items():
        if curves is None or curves.columns.shape[1] != latest.columns.shape[1]:
            continue
        style = STYLES.get(name)
        for j, column in enumerate(_resampled(curves, t, count)):
            data.append(column)
            if style is None:  # a kept run
                stroke, width, dash = KEPT_STROKE, 1.2, [8, 4]
            else:
                stroke, width, dash = COLORS[j % len(COLORS)] + style[0], style[1], style[2]
            series.append(
                {"label": f"{latest.names[j]} ({name})", "stroke": stroke, "width": width, "dash": dash}
            )
    return tuple(data), tuple(series)


class Plots:
    """The panels in ``server``'s GUI, in ``folder`` (a Viser folder or tab handle; None: the
    GUI's top level). Drawn from one thread at a time (a container is entered by one)."""

    def __init__(self, server: Any, folder: Any = None) -> None:
        self._server = server
        self._folder = folder
        self._lock = threading.Lock()
        self._handles: dict[str, Any] = {}
        self._orders: dict[str, int] = {}
        self._cache: list[tuple[Finished, Panels]] = []

    def show(self, done: Finished, references: dict[str, Finished | None] | None = None) -> None:
        """Redraw every panel for ``done`` beside ``references`` (name → run; a panel this
        run has no data for is hidden)."""
        theirs = {
            name: (None if run is None else self._panels(run)) for name, run in (references or {}).items()
        }
        wanted = {
            title: compose(curves, {name: (p or {}).get(title) for name, p in theirs.items()})
            for title, curves in self._panels(done).items()
        }
        self._draw(wanted, hide_others=True)

    def _panels(self, run: Finished) -> Panels:
        """:func:`panels` of ``run``, kept for the runs drawn again (previous, defaults, kept)."""
        for seen, out in self._cache:
            if seen is run:
                return out
        out = panels(run)
        self._cache = [*self._cache[-5:], (run, out)]
        return out

    def show_partial(self, part: Partial) -> None:
        """Redraw the joint-error and torque panels for the part of a run simulated so far."""
        wanted = joint_panels(part.t, part.q, part.q_des, part.tau_command, part.torque_limits)
        self._draw({title: compose(curves) for title, curves in wanted.items()}, False)

    def _draw(self, wanted: dict[str, tuple[Any, Any]], hide_others: bool) -> None:
        with self._lock, self._server.atomic():
            if hide_others:
                for title, handle in self._handles.items():
                    handle.visible = title in wanted
            for title, (data, series) in wanted.items():
                handle = self._handles.get(title)
                if handle is not None:
                    if [s["label"] for s in handle.series] != [s["label"] for s in series]:
                        handle.series = series
                    handle.data = data
                    handle.visible = True
                    continue
                order = self._orders.setdefault(title, len(self._orders))
                with self._folder if self._folder is not None else contextlib.nullcontext():
                    self._handles[title] = self._server.gui.add_uplot(
                        data, series, title=title, aspect=1.6, scales=X_SCALE, order=100.0 + order
                    )


__all__ = ["Curves", "Plots", "compose", "joint_panels", "panels"]
