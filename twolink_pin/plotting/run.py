"""Figures of one closed-loop run: each joint's state, the torques, and the parameter
estimates of laws that estimate parameters.

:func:`save_simulation_figures` writes ``<prefix>_theta1.png``, …, ``<prefix>_theta1dot.png``,
…, ``<prefix>_torque.png`` and, for runs with estimates, ``<prefix>_param_error.png``
(``inertial`` parameters) and ``<prefix>_friction_error.png`` (``friction`` ones), as the
result's ``parameter_kinds`` declare (drawn by :mod:`twolink_pin.plotting.parameters`).
:func:`_simulation_figures` returns the figures keyed by those suffixes (the keys of
``figure_numbers``). Time [s], angles [rad], rates [rad/s], torques [N·m]; parameters in
the result's ``parameter_units``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.plotting._panels import (
    LEGEND_BOX,
    NOTE_BOX,
    envelope,
    free_spot,
    limit_lines,
    plain_log_ticks,
    shade_spans,
    unblock_legends,
)
from twolink_pin.plotting._save import save_figures
from twolink_pin.plotting._style import (
    ACTUAL_COLOR,
    COMMAND_COLOR,
    DESIRED_COLOR,
    ERROR_COLOR,
    LIMIT_COLOR,
    LOG_FLOOR,
    SIM_TORQUE_FIGSIZE,
    SIM_TORQUE_MARGINS,
    STATE_FIGSIZE,
    STATE_MARGINS,
    check_figure_numbers,
    figure_title,
    fix_margins,
    new_figure,
    rows_figsize,
)
from twolink_pin.plotting.parameters import check_parameters, parameter_figures
from twolink_pin.simulation import SimulationResult

SIM_TORQUE_ROW_HEIGHT = 2.75
"""Height each further (or fewer) joint adds to (takes from) a run's torque figure [in]."""


def _heading(result: SimulationResult, title: str | None) -> str:
    """First title line: the controller's name and, if given, its long title."""
    return f"controller {result.controller}" + (f" ({title})" if title and title != result.controller else "")


def _late_ylim(ax: Axes, y: np.ndarray) -> None:
    """y range of ``y`` padded by 12 % (symmetric and tiny if ``y`` is all zero)."""
    lo, hi = float(y.min()), float(y.max())
    pad = 0.12 * (hi - lo) or 0.12 * max(abs(lo), abs(hi)) or 1e-15
    ax.set_ylim(lo - pad, hi + pad)


# ------------------------------------------------------------------------- state


def _state_figure(
    result: SimulationResult, j: int, derivative: bool, figure_numbers: Mapping[str, int], heading: str
) -> Figure:
    """Joint ``j``'s position (or velocity): actual vs desired, error early and late, log |error|."""
    t = result.t
    if derivative:
        actual, desired, error = result.v[:, j], result.v_des[:, j], result.edot[:, j]
        base, ebase, unit = r"\dot\theta", r"\dot e", "rad/s"
    else:
        actual, desired, error = result.q[:, j], result.q_des[:, j], result.e[:, j]
        base, ebase, unit = r"\theta", "e", "rad"
    sym, sym_d, esym = f"{base}_{{{j + 1}}}", f"{base}_{{{j + 1},d}}", f"{ebase}_{{{j + 1}}}"
    duration = float(t[-1] - t[0])
    split = float(t[0] + min(result.reference_period, duration / 3.0))
    margin = 0.01 * duration  # keeps what happens at t = 0 off the axis spine

    fig = new_figure(STATE_FIGSIZE)
    axd = fig.subplot_mosaic(
        [["signal", "signal"], ["error", "error-late"], ["error-log", "error-log"]],
        height_ratios=(1.5, 1.0, 1.0),
        width_ratios=(1.0, 2.0),
    )
    top, early, late, log = axd["signal"], axd["error"], axd["error-late"], axd["error-log"]
    top.sharex(log)
    top.tick_params(labelbottom=False)

    top.plot(t, actual, color=ACTUAL_COLOR, lw=2.6, alpha=0.75, label=f"actual ${sym}$")
    top.plot(t, desired, color=DESIRED_COLOR, lw=1.0, ls="--", label=f"desired ${sym_d}$")
    top.set_ylabel(f"${sym}$ [{unit}]")
    top.legend(loc="upper right", fontsize=8, ncols=2, framealpha=0.9)
    span = float(max(np.ptp(actual), np.ptp(desired)) or 1.0)
    lo, hi = float(min(actual.min(), desired.min())), float(max(actual.max(), desired.max()))
    top.set_ylim(lo - 0.08 * span, hi + 0.35 * span)  # head room for the legend

    for ax in (early, late):
        ax.plot(t, error, color=ERROR_COLOR, lw=1.2, label=f"${esym} = {sym} - {sym_d}$")
        ax.axhline(0.0, color="0.6", lw=0.7)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
    early.set_xlim(t[0] - margin / 3.0, split)
    _late_ylim(early, error[t <= split])
    early.set_ylabel(f"${esym}$ [{unit}]")
    early.set_title(f"${esym} = {sym} - {sym_d}$, first {split - t[0]:g} s", fontsize=9)
    after = t >= split
    late.set_xlim(split, t[-1])
    _late_ylim(late, error[after] if after.any() else error)
    late.set_title(f"${esym}$ for t ≥ {split:g} s (own scale)", fontsize=9)

    te, env = envelope(t, error)
    log.semilogy(
        te, env, color=ERROR_COLOR, lw=1.2, drawstyle="steps-post", label=f"max $|{esym}|$ per window"
    )
    plain_log_ticks(log)
    log.set_ylim(max(LOG_FLOOR, 0.3 * float(env.min())), 3.0 * float(env.max()))
    width = float(te[1] - te[0]) if len(te) > 1 else duration
    log.set_ylabel(f"$|{esym}|$ [{unit}]")
    log.legend(loc="upper right", fontsize=8, title=f"window {width:.3g} s", title_fontsize=8)
    log.set_xlabel("t [s]")
    log.set_xlim(t[0] - margin, t[-1])
    for ax in (top, early, late, log):
        ax.grid(True, alpha=0.3)
    for ax in (early, late):
        ax.set_xlabel("t [s]", fontsize=9)
    what = "velocity" if derivative else "position"
    key = f"theta{j + 1}{'dot' if derivative else ''}"
    fig.suptitle(
        figure_title(f"joint {j + 1} {what}: actual vs desired, error", key, figure_numbers, heading),
        fontsize=11,
    )
    fix_margins(fig, STATE_MARGINS)
    return fig


# ------------------------------------------------------------------------ torque


def _torque_figure(
    result: SimulationResult, figure_numbers: Mapping[str, int] | None = None, heading: str | None = None
) -> Figure:
    """Applied (and commanded, if clipped) torque per joint: whole run and last period."""
    t = result.t
    nv = result.tau.shape[1]
    fig = new_figure(rows_figsize(SIM_TORQUE_FIGSIZE, nv, SIM_TORQUE_ROW_HEIGHT))
    axes = fig.subplots(nv, 2, sharex="col", width_ratios=(1.6, 1.0), squeeze=False)
    period = result.reference_period
    last = t >= max(t[0], t[-1] - period)
    clipped = result.saturate and not np.array_equal(result.tau, result.tau_command)
    for j in range(nv):
        limit = float(result.torque_limits[j])
        for col, mask in ((0, np.ones_like(t, dtype=bool)), (1, last)):
            ax = axes[j, col]
            ax.set_label(f"tau{j + 1}" if col == 0 else f"tau{j + 1}-last")
            tt = t[mask]
            command = result.tau_command[mask, j]
            if clipped:
                ax.plot(tt, command, color=COMMAND_COLOR, lw=1.0, ls="--", label="commanded")
            ax.plot(tt, result.tau[mask, j], color=ACTUAL_COLOR, lw=1.3, label=rf"applied $\tau_{{{j + 1}}}$")
            peak_cmd = float(np.abs(command).max())
            limit_lines(ax, limit, peak_cmd)
            ax.axhline(0.0, color="0.8", lw=0.6)
            ax.grid(True, alpha=0.3)
            ax.set_xlim(tt[0] - (0.01 * (tt[-1] - tt[0]) if col == 0 else 0.0), tt[-1])
            over = np.abs(command) > limit
            if over.any():
                k = int(np.argmax(np.abs(command)))
                tk, yk = float(tt[k]), float(command[k])
                note = "clipped by the plant" if result.saturate else "not saturated in this run"
                lines = np.linspace(tt[0], tt[-1], 200)
                spot = free_spot(
                    ax,
                    np.concatenate([tt, lines, lines]),
                    np.concatenate([result.tau[mask, j], np.full(200, limit), np.full(200, -limit)]),
                    (0.5, 0.2),
                    (tk, yk),
                    (LEGEND_BOX, NOTE_BOX),
                )
                ax.annotate(
                    f"commanded |τ{j + 1}| up to {peak_cmd:.3g} N·m > {limit:g} N·m\n"
                    f"(first at t = {tt[np.argmax(over)]:.3f} s; {note})",
                    (tk, yk),
                    textcoords="axes fraction",
                    xytext=spot,
                    ha="center",
                    va="center",
                    fontsize=8,
                    color=LIMIT_COLOR,
                    arrowprops={"arrowstyle": "->", "color": LIMIT_COLOR},
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": LIMIT_COLOR},
                )
        axes[j, 0].set_ylabel(rf"$\tau_{{{j + 1}}}$ [N·m]")
        axes[j, 0].legend(loc="upper right", fontsize=8)
    axes[0, 0].set_title("whole run", fontsize=10)
    axes[0, 1].set_title(f"last reference period ({period:g} s), own scale", fontsize=10)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    sat = "saturated at the limits" if result.saturate else "no saturation"
    heading = heading if heading is not None else _heading(result, None)
    fig.suptitle(figure_title(f"joint torques ({sat})", "torque", figure_numbers or {}, heading), fontsize=11)
    fix_margins(fig, SIM_TORQUE_MARGINS)
    shown = np.concatenate([result.tau, result.tau_command]) if clipped else result.tau
    times = np.concatenate([t, t]) if clipped else t
    unblock_legends(fig, [(axes[j, 0], times, shown[:, j]) for j in range(nv)])
    return fig


# ------------------------------------------------------------------------ a run


def _simulation_figures(
    result: SimulationResult, figure_numbers: Mapping[str, int] | None = None, title: str | None = None
) -> dict[str, Figure]:
    """Build one run's figures.

    Returns:
        Suffix → figure: ``theta{i}`` for each joint, then ``theta{i}dot``, ``torque``, and
        for runs with parameter estimates ``param_error`` (the parameters whose
        ``parameter_kinds`` entry is ``"inertial"``) and ``friction_error`` (``"friction"``),
        each only when it has a parameter; ``state`` for a law with other state (an
        integrator, a filter: :mod:`twolink_pin.plotting.state`).

    Raises:
        InvalidParameterError: ``figure_numbers`` is not a mapping of key → positive
            integer, ``title`` is not a string, or the result lacks a name, unit or known
            kind for an estimated parameter.
    """
    numbers = check_figure_numbers(figure_numbers)
    if title is not None and not isinstance(title, str):
        raise InvalidParameterError("title", title, "a string (the law's display title) or None")
    if result.p_error is not None:
        check_parameters(result)  # before drawing anything
    heading = _heading(result, title)
    nv = result.nv
    figures: dict[str, Figure] = {}
    for j in range(nv):
        figures[f"theta{j + 1}"] = _state_figure(result, j, False, numbers, heading)
    for j in range(nv):
        figures[f"theta{j + 1}dot"] = _state_figure(result, j, True, numbers, heading)
    figures["torque"] = _torque_figure(result, numbers, heading)
    if result.p_error is not None:
        figures |= parameter_figures(result, numbers, heading)
    from twolink_pin.plotting.state import state_figure

    state = state_figure(result, heading)
    if state is not None:
        figures["state"] = state
    return figures


def wrench_spans(wrench: Any) -> tuple[tuple[float, float], ...]:
    """The time window ``(start, stop)`` [s] of a plant's wrench (``start``/``stop`` attributes,
    as :class:`~twolink_pin.disturbances.Wrench` has them) as the ``spans`` the run figures
    shade; none without a wrench."""
    return () if wrench is None else ((float(wrench.start), float(wrench.stop)),)


def save_simulation_figures(
    result: SimulationResult,
    out_dir: str | os.PathLike[str],
    prefix: str | None = None,
    figure_numbers: Mapping[str, int] | None = None,
    title: str | None = None,
    spans: Sequence[tuple[float, float]] = (),
) -> list[Path]:
    """Write one run's figures as PNG into ``out_dir``.

    * ``<prefix>_theta1.png``, … (position [rad]) and ``<prefix>_theta1dot.png``, …
      (velocity [rad/s]), one per joint: actual vs desired over the run; the error over the
      first reference period and, on its own scale, after it; the error's envelope
      ``max |e|`` per window on a log scale (errors decaying to 1e-10 stay visible);
    * ``<prefix>_torque.png``: each ``τ_i`` [N·m] with its ``±limit`` lines (applied vs
      commanded when the plant saturates), for the whole run and the last reference period;
      a limit far beyond the data is noted instead of squashing the curve, a commanded
      torque beyond its limit is annotated, and a legend that would cover the curve moves
      to a free corner or side; the figure grows by 2.75 in per joint;
    * runs with parameter estimates: ``<prefix>_param_error.png`` (``p̂ − p`` of the
      ``"inertial"`` parameters, one panel per unit of ``result.parameter_units``, and the
      relative error [%]) and ``<prefix>_friction_error.png`` (the same for the
      ``"friction"`` ones, e.g. V [N·m·s/rad] and C [N·m]), as ``result.parameter_kinds``
      declares. A figure of more than 8 parameters (the base parameters of a 6- or 7-joint
      arm) shows instead the normalised error ``‖p̂ − p‖ / ‖p‖`` of each unit over time and
      the error of each parameter at the start and the end as bars, labelled ``β<k>``
      (:func:`twolink_pin.plotting.parameters._parameter_summary_figure`). Relative errors
      only where ``|p_i|`` is at least 1 % of the largest ``|p_j|`` of its unit;
    * a law with state other than estimates (``pid``'s integrals): ``<prefix>_state.png``.

    Args:
        result: A simulation result (read only).
        out_dir: Output directory, created if missing.
        prefix: File-name prefix; default ``result.controller``; ``""`` for none.
        figure_numbers: Suffix (``theta1``, ``theta1dot``, ``torque``, ``param_error``,
            ``friction_error``, …) → the number of the matching figure in a report, cited in
            the title as "cf. report Fig. N"; keys of no figure are ignored. Default: none.
        title: The law's display title, shown beside its name in every title
            (e.g. ``"PD + model feedforward"``). Default: the name only.
        spans: Time windows ``(start, stop)`` [s] in which a wrench pushes the arm, shaded
            on the time axes of the joint and torque figures. Default: none.

    Returns:
        The paths written, in figure order.

    Raises:
        InvalidParameterError: see :func:`_simulation_figures`.
        OutputError: ``out_dir`` cannot be created or written.
    """
    figures = _simulation_figures(result, figure_numbers, title)
    for key, fig in figures.items():
        if key.startswith("theta") or key == "torque":
            shade_spans(fig, spans, result.t)
    prefix = result.controller if prefix is None else prefix
    return save_figures(figures, out_dir, f"{prefix}_" if prefix else "")
