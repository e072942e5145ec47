"""Figures of parameter identification: the validation torques, the estimates, an excitation,
how adaptive estimates converge along different trajectories, and a Monte Carlo's coverage.

* :func:`save_identification_figures` — ``<prefix>validation.png`` (each joint's measured,
  filtered and predicted torque on the validation period, and the prediction error) and
  ``<prefix>estimates.png`` (each estimate's error in standard deviations when the truth is
  known, else its relative standard deviation);
* :func:`save_excitation_figures` — ``excitation.png``: each joint's q, q̇, q̈ and torque
  over one period against the limits;
* :func:`save_convergence_figure` — ``|p̂_i − p_i| / |p_i|`` of adaptive runs along several
  trajectories, the 5 % line, and the averaged model's prediction;
* :func:`save_coverage_figure` — the normalised errors ``(θ̂ − θ)/σ`` of a Monte Carlo over
  noise seeds against N(0, 1), and each parameter's ±3σ coverage.

Time [s], angles [rad], rates [rad/s], torques [N·m].
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.limits import joint_limits
from twolink_pin.plotting._panels import plain_log_ticks
from twolink_pin.plotting._save import save_figure, save_figures
from twolink_pin.plotting._style import (
    ACTUAL_COLOR,
    COMMAND_COLOR,
    DESIRED_COLOR,
    ERROR_COLOR,
    LIMIT_COLOR,
    Margins,
    fix_margins,
    new_figure,
)

ROW_HEIGHT = 2.3
"""Height of one joint's row [in]."""
WIDTH = 11.0
"""Width of the identification figures [in]."""
SHOWN_SECONDS = 10.0
"""Longest stretch of the validation period drawn [s] (its start)."""
LABEL_CHARACTERS = 34
"""Parameter names are cut to this many characters on an axis."""
VALIDATION_MARGINS = Margins(left=0.8, right=0.12, bottom=0.5, top=0.75, wspace=0.95, hspace=0.6)
"""The validation figure [in]: a two-line suptitle, the error panels' titles and y labels."""
EXCITATION_MARGINS = Margins(left=0.65, right=0.15, bottom=0.5, top=0.5, wspace=0.55, hspace=0.2)
"""The excitation figure [in]: one suptitle line and the column titles above, a row per joint."""
CONVERGENCE_MARGINS = Margins(left=0.85, right=0.12, bottom=0.5, top=0.95, hspace=0.58)
"""The convergence figure [in]: a two-line suptitle, a titled panel per run."""


def _short(name: str) -> str:
    return name if len(name) <= LABEL_CHARACTERS else name[: LABEL_CHARACTERS - 1] + "…"


def _validation_figure(identification: Any) -> Figure:
    validation = identification.validation
    nv = validation.tau_measured.shape[1]
    fig = new_figure((WIDTH, 1.2 + ROW_HEIGHT * nv))
    axes = fig.subplots(nv, 2, squeeze=False, width_ratios=(3.0, 1.4))
    t = validation.t
    shown = t <= t[0] + SHOWN_SECONDS
    for j in range(nv):
        ax, err_ax = axes[j]
        ax.plot(t[shown], validation.tau_measured[shown, j], color="0.75", lw=0.8, label="measured (logged)")
        ax.plot(
            t[shown],
            validation.tau_filtered[shown, j],
            color=ACTUAL_COLOR,
            lw=1.4,
            label="measured, filtered",
        )
        ax.plot(
            t[shown],
            validation.tau_predicted[shown, j],
            "--",
            color=COMMAND_COLOR,
            lw=1.4,
            label="predicted W θ̂",
        )
        ax.set_ylabel(rf"$\tau_{{{j + 1}}}$ [N·m]")
        ax.grid(True, alpha=0.3)
        if j == 0:
            ax.legend(loc="upper right", fontsize=8, ncols=3)
        error = validation.tau_filtered[:, j] - validation.tau_predicted[:, j]
        err_ax.plot(t, np.where(validation.valid, error, np.nan), color=ERROR_COLOR, lw=0.8)
        err_ax.set_ylabel(rf"$\tau_{{{j + 1}}}$ error [N·m]")
        err_ax.grid(True, alpha=0.3)
        err_ax.set_title(f"RMS {validation.rms[j]:.3g} N·m", fontsize=9)
    axes[-1, 0].set_xlabel("t [s]")
    axes[-1, 1].set_xlabel("t [s]")
    fig.suptitle(
        f"{identification.robot}: torque predicted by the identified model on the validation period "
        f"({t[0]:.3g}–{t[-1]:.3g} s, not fitted)\nfiltered at {identification.cutoff_hz:g} Hz; "
        f"condition number {identification.condition_number:.3g}"
    )
    fix_margins(fig, VALIDATION_MARGINS)
    return fig


def _estimates_figure(identification: Any) -> Figure:
    n = identification.size
    fig = new_figure((WIDTH, 1.6 + 0.32 * n))
    ax = fig.subplots()
    y = np.arange(n)[::-1]
    labels = [f"{_short(name)} [{unit}]" for name, unit in zip(identification.names, identification.units)]
    if identification.true is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            z = (identification.estimate - identification.true) / identification.std
        z = np.where(np.isfinite(z), z, 0.0)
        inside = np.abs(z) <= 3
        ax.barh(y, z, color=np.where(inside, ACTUAL_COLOR, ERROR_COLOR), height=0.6)
        for k in (-3, 3):
            ax.axvline(k, color=LIMIT_COLOR, ls="--", lw=1.0)
        ax.axvline(0, color=DESIRED_COLOR, lw=0.8)
        bound = max(4.0, float(np.abs(z).max()) * 1.1)
        ax.set_xlim(-bound, bound)
        ax.set_xlabel("(estimate − true) / σ")
        title = f"{int(inside.sum())} of {n} true values within ±3σ of their estimates"
    else:
        rel = np.minimum(identification.relative_std, 1e3)
        ax.barh(y, rel, color=np.where(rel <= 10, ACTUAL_COLOR, ERROR_COLOR), height=0.6)
        ax.axvline(10, color=LIMIT_COLOR, ls="--", lw=1.0, label="10 %: poorly identified beyond")
        ax.set_xscale("log")
        ax.set_xlabel("relative standard deviation 100 σ / |θ̂| [%]")
        ax.legend(loc="lower right", fontsize=8)
        title = "relative standard deviation of each estimate"
    ax.set_yticks(y, labels, fontsize=8)
    ax.grid(True, axis="x", alpha=0.3)
    fig.suptitle(f"{identification.robot}: identified parameters — {title}")
    return fig


def _identification_figures(identification: Any) -> dict[str, Figure]:
    """The figures keyed ``validation`` (if the identification has a validation period) and
    ``estimates``."""
    figures: dict[str, Figure] = {}
    if identification.validation is not None:
        figures["validation"] = _validation_figure(identification)
    figures["estimates"] = _estimates_figure(identification)
    return figures


def save_identification_figures(
    identification: Any, out_dir: str | os.PathLike[str], prefix: str = "identification_"
) -> list[Path]:
    """Write ``<prefix>validation.png`` and ``<prefix>estimates.png`` into ``out_dir``.

    Args:
        identification: An :class:`~twolink_pin.identification.least_squares.Identification`.
        out_dir: Output folder, created if missing.
        prefix: File name prefix.

    Returns:
        The paths written.
    """
    return save_figures(_identification_figures(identification), out_dir, prefix)


def _excitation_figure(
    robot: Any, trajectory: Any, limits: Mapping[str, Sequence[float]] | None, check: Any
) -> Figure:
    nv = trajectory.nv
    t = trajectory.t0 + np.linspace(0.0, trajectory.period, 2001)
    ref = trajectory.sample(t)
    tau = np.asarray(check.tau)
    fig = new_figure((WIDTH, 1.0 + 1.9 * nv))
    axes = fig.subplots(nv, 4, squeeze=False, sharex=True)
    if limits is None:  # the robot's own, read once (twolink_pin.limits)
        own = joint_limits(robot)
        bounds = {
            "lower": own.position_lower,
            "upper": own.position_upper,
            "velocity": own.velocity,
            "acceleration": own.acceleration,
            "torque": own.effort,
        }
    else:
        bounds = {k: np.asarray(v, dtype=float) for k, v in limits.items()}
    names = ("q [rad]", "q̇ [rad/s]", "q̈ [rad/s²]", "τ [N·m]")
    keys = (None, "velocity", "acceleration", "torque")
    for j in range(nv):
        series = (ref.q[:, j], ref.v[:, j], ref.a[:, j], tau[:, j])
        times = (t, t, t, np.asarray(check.t))
        for c, (x, tc) in enumerate(zip(series, times)):
            ax = axes[j, c]
            ax.plot(tc, x, color=ACTUAL_COLOR, lw=1.3)
            peak = float(np.abs(x).max()) or 1.0
            if c == 0:
                lo, hi = float(bounds["lower"][j]), float(bounds["upper"][j])
                span = float(np.ptp(x)) or 1.0
                bottom, top = float(x.min()) - 0.25 * span, float(x.max()) + 0.25 * span
                for value in (lo, hi):
                    if math.isfinite(value):
                        ax.axhline(value, color=LIMIT_COLOR, ls="--", lw=1.0)
                        bottom, top = min(bottom, value - 0.08 * span), max(top, value + 0.08 * span)
                ax.set_ylim(bottom, top)
            else:
                key = keys[c]
                assert key is not None
                bound = float(bounds[key][j])
                if math.isfinite(bound) and bound <= 3.0 * peak:
                    ax.axhline(bound, color=LIMIT_COLOR, ls="--", lw=1.0)
                    ax.axhline(-bound, color=LIMIT_COLOR, ls="--", lw=1.0)
                    ax.set_ylim(-1.15 * bound, 1.15 * bound)
                else:
                    ax.set_ylim(-1.3 * peak, 1.3 * peak)
                    if math.isfinite(bound):
                        ax.text(
                            0.02,
                            0.03,
                            f"limit ±{bound:.3g} off scale",
                            transform=ax.transAxes,
                            fontsize=8,
                            color=LIMIT_COLOR,
                        )
            ax.grid(True, alpha=0.3)
            if j == 0:
                ax.set_title(names[c], fontsize=10)
            if c == 0:
                ax.set_ylabel(f"joint {j + 1}")
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    extra = (
        f"Fourier series, {trajectory.harmonics} harmonics, period {trajectory.period:g} s"
        if hasattr(trajectory, "harmonics")
        else f"period {trajectory.period:g} s"
    )
    which = "the limits it was designed within" if limits is not None else "the URDF's limits"
    if limits is None and np.isfinite(bounds["acceleration"]).any():
        which += " and the profile's accelerations"
    fig.suptitle(f"{robot.name}: excitation ({extra}) over one period; dashed: {which}")
    fix_margins(fig, EXCITATION_MARGINS)
    return fig


def save_excitation_figures(
    robot: Any,
    trajectory: Any,
    out_dir: str | os.PathLike[str],
    limits: Mapping[str, Sequence[float]] | None = None,
    check: Any = None,
) -> list[Path]:
    """Write ``excitation.png`` into ``out_dir``: each joint's q, q̇, q̈ and the torque the
    motion needs (rigid body, :func:`twolink_pin.feasibility.check_torques`, or ``check``)
    over one period, the limits dashed: ``limits`` as
    :meth:`~twolink_pin.identification.excitation.ExcitationLimits.resolve` gives them (the
    bounds an excitation was designed within), else the robot's own
    (:func:`twolink_pin.limits.joint_limits`: the URDF's position, velocity and effort limits,
    the profile's acceleration limits). A limit more than 3 × the peak is noted, not drawn."""
    if check is None:
        from twolink_pin.feasibility import check_torques

        check = check_torques(robot, trajectory)
    return save_figures({"excitation": _excitation_figure(robot, trajectory, limits, check)}, out_dir, "")


def _convergence_figure(runs: Mapping[str, Mapping[str, Any]], fraction: float, title: str | None) -> Figure:
    panels = len(runs)
    fig = new_figure((WIDTH, 1.2 + 2.6 * panels))
    axes = fig.subplots(panels, 1, squeeze=False)[:, 0]
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink")
    for ax, (label, run) in zip(axes, runs.items()):
        t = np.asarray(run["t"])
        error = np.abs(np.asarray(run["p_hat"]) - np.asarray(run["p_true"])) / np.abs(
            np.asarray(run["p_true"])
        )
        step = max(1, t.size // 3000)
        for i, name in enumerate(run["names"]):
            ax.semilogy(
                t[::step],
                np.maximum(error[::step, i], 1e-12),
                color=colors[i % len(colors)],
                lw=1.4,
                label=name,
            )
        predicted = run.get("predicted")
        if predicted is not None:
            tp, ep = (
                np.asarray(predicted[0]),
                np.abs(np.asarray(predicted[1])) / np.abs(np.asarray(run["p_true"])),
            )
            for i in range(ep.shape[1]):
                ax.semilogy(tp, np.maximum(ep[:, i], 1e-12), ":", color=colors[i % len(colors)], lw=1.2)
        ax.axhline(fraction, color=LIMIT_COLOR, ls="--", lw=1.0, label=f"{100 * fraction:g} %")
        reached = run.get("time_within")
        note = (
            f"within {100 * fraction:g} % from t = {reached:.3g} s"
            if reached is not None
            else f"not within {100 * fraction:g} % in {t[-1]:.3g} s"
        )
        extra = run.get("note")
        ax.set_title(f"{label}: {note}" + (f"; {extra}" if extra else ""), fontsize=10)
        ax.set_ylabel("|p̂ − p| / |p|")
        ax.set_ylim(1e-10, 10.0)
        plain_log_ticks(ax)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(loc="lower left", fontsize=8, ncols=len(run["names"]) + 1)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(
        title
        or "adaptive estimates along different references (solid: simulated; dotted: averaged model exp(−ΓG t))"
    )
    fix_margins(fig, CONVERGENCE_MARGINS)
    return fig


def save_convergence_figure(
    runs: Mapping[str, Mapping[str, Any]],
    path: str | os.PathLike[str],
    fraction: float = 0.05,
    title: str | None = None,
) -> Path:
    """Write one panel per run of ``runs`` (label → ``{"t", "p_hat", "p_true", "names"}``, and
    optionally ``"predicted": (t, p̃)``, ``"time_within"`` [s] or None, ``"note"``): each
    estimate's relative error on a log scale, the ``fraction`` line, the averaged model dotted.

    Raises:
        InvalidParameterError: no runs.
    """
    if not runs:
        raise InvalidParameterError("runs", runs, "at least one run")
    fig = _convergence_figure(runs, fraction, title)
    return save_figure(fig, Path(path))


def _coverage_figure(z: np.ndarray, names: Sequence[str], title: str) -> Figure:
    fig = new_figure((WIDTH, 4.6))
    hist, bars = fig.subplots(1, 2, width_ratios=(1.2, 1.0))
    pooled = z.ravel()
    pooled = pooled[np.isfinite(pooled)]
    edges = np.linspace(-5, 5, 41)
    hist.hist(
        np.clip(pooled, -5, 5), bins=edges, density=True, color=ACTUAL_COLOR, alpha=0.7, label="(θ̂ − θ)/σ"
    )
    x = np.linspace(-5, 5, 400)
    hist.plot(x, np.exp(-0.5 * x * x) / math.sqrt(2 * math.pi), color=DESIRED_COLOR, lw=1.4, label="N(0, 1)")
    for k in (-3, 3):
        hist.axvline(k, color=LIMIT_COLOR, ls="--", lw=1.0)
    hist.set_xlabel("normalised error (clipped to ±5)")
    hist.legend(loc="upper right", fontsize=8)
    hist.set_title(
        f"all parameters, {z.shape[0]} seeds: {100 * np.mean(np.abs(pooled) <= 3):.1f} % within ±3σ",
        fontsize=10,
    )
    coverage = 100 * np.mean(np.abs(z) <= 3, axis=0)
    y = np.arange(len(names))[::-1]
    bars.barh(y, coverage, color=np.where(coverage >= 90, ACTUAL_COLOR, ERROR_COLOR), height=0.6)
    bars.axvline(99.73, color=LIMIT_COLOR, ls="--", lw=1.0, label="99.7 % (Gaussian)")
    bars.set_yticks(y, [_short(n) for n in names], fontsize=8)
    bars.set_xlim(0, 100)
    bars.set_xlabel("seeds with the true value within ±3σ [%]")
    bars.legend(loc="lower left", fontsize=8)
    bars.grid(True, axis="x", alpha=0.3)
    fig.suptitle(title)
    return fig


def save_coverage_figure(
    z: np.ndarray,
    names: Sequence[str],
    path: str | os.PathLike[str],
    title: str = "Monte Carlo over noise seeds",
) -> Path:
    """Write the histogram of ``z = (θ̂ − θ) / σ`` (shape (seeds, n_θ)) against N(0, 1) and each
    parameter's ±3σ coverage [%] to ``path``."""
    z = np.asarray(z, dtype=float)
    if z.ndim != 2 or z.shape[1] != len(names):
        raise InvalidParameterError("z", f"shape {z.shape}", f"(seeds, {len(names)}): one column per name")
    fig = _coverage_figure(z, names, title)
    return save_figure(fig, Path(path))
