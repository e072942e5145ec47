"""Figures of the parameter estimates of one run: ``p̂ − p`` of the ``inertial`` parameters
(``param_error``) and of the ``friction`` ones (``friction_error``), as the result's
``parameter_kinds`` declare.

Two layouts, by the number of parameters n in the figure:

* n <= :data:`MANY_PARAMETERS` (the twolink's p1, p2, p3 and V1, V2, C1, C2): one curve
  per parameter, ``p̂_i − p_i`` in one panel per unit, then ``(p̂_i − p_i)/p_i`` [%];
* n > :data:`MANY_PARAMETERS` (the base parameters of a 6- or 7-joint arm: 36 on the UR5,
  43 on the Panda): the normalised error ``‖p̂ − p‖ / ‖p‖`` of each unit's parameters over
  time, and one bar pair per parameter (its error at the start and at the end), labelled
  ``β<k>`` with the first term of its name and its final relative error.

In both, a relative error is shown only where the true value is not negligible
(:data:`RELATIVE_FLOOR`). Parameters in the result's ``parameter_units`` (kg·m², kg·m,
N·m·s/rad, N·m, …); time [s].
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError
from twolink_pin.plotting._panels import unblock_legends
from twolink_pin.plotting._style import (
    ACTUAL_COLOR,
    BAR_HEIGHT,
    NORM_PANEL_HEIGHT,
    PANEL_DECORATION_HEIGHT,
    PARAM_FIGSIZE,
    PARAM_MARGINS,
    PARAM_ROW_HEIGHT,
    SUMMARY_WIDTH,
    SUPTITLE_HEIGHT,
    figure_title,
    fix_margins,
    new_figure,
)
from twolink_pin.simulation import SimulationResult

PARAMETER_KINDS = ("inertial", "friction")
"""The kinds of estimated parameters, in figure order."""
PARAMETER_FIGURES = {"inertial": "param_error", "friction": "friction_error"}
"""Figure key of each parameter kind."""
INLINE_LEGEND_ENTRIES = 4
"""A panel with more lines than this gets its legend outside, on the right."""
DETAILED_LEGEND_ENTRIES = 12
"""A panel with more lines than this lists only the names (no true value, no start → end)."""
LEGEND_ROWS = 12
"""Most entries per column of an outside legend."""
MANY_PARAMETERS = 8
"""A figure of more parameters than this shows norms and bars instead of one curve each."""
RELATIVE_FLOOR = 0.01
"""A true value ``|p_i|`` below this fraction of the largest ``|p_j|`` of the same unit in the
figure is negligible: its relative error ``(p̂_i − p_i)/p_i`` is not shown (it would divide
by a value near 0: a zero product of inertia, a first moment of a link centred on its axis)."""
LABEL_CHARS = 34
"""Longest label beside a bar [characters]; a longer one is cut with "…"."""
INITIAL_COLOR = "0.78"
"""Colour of the bars of the initial error ``p̂(0) − p``."""


# ------------------------------------------------------------------------- shared


def _is_indexed(name: str) -> bool:
    """Whether ``name`` is one ASCII letter then digits (``p1``, ``V2``, ``C12``)."""
    return len(name) >= 2 and name[0].isascii() and name[0].isalpha() and name[1:].isdigit()


def _parameter_symbol(name: str) -> str:
    """``p_1`` in mathtext for ``p1``; any other name as it is."""
    return rf"${name[0]}_{{{name[1:]}}}$" if _is_indexed(name) else name


def check_parameters(result: SimulationResult) -> None:
    """The result declares a name, a unit and a known kind for every estimated parameter.

    Raises:
        InvalidParameterError: a declaration is missing or a kind is unknown.
    """
    assert result.p_hat is not None
    n_p = result.p_hat.shape[1]
    for field in ("parameter_names", "parameter_units", "parameter_kinds"):
        values = getattr(result, field)
        if len(values) != n_p:
            raise InvalidParameterError(
                f"result.{field}", values, f"one entry per estimated parameter ({n_p}) but got {len(values)}"
            )
    unknown = sorted(set(result.parameter_kinds) - set(PARAMETER_KINDS))
    if unknown:
        raise InvalidParameterError(
            "result.parameter_kinds", result.parameter_kinds, f"each one of {PARAMETER_KINDS}, not {unknown}"
        )


def _unit_groups(units: Sequence[str], columns: Sequence[int]) -> dict[str, list[int]]:
    """The parameters ``columns`` grouped by unit, units in order of first use."""
    groups: dict[str, list[int]] = {}
    for i in columns:
        groups.setdefault(units[i], []).append(i)
    return groups


def _relative_columns(p_true: np.ndarray, units: Sequence[str], columns: Sequence[int]) -> list[int]:
    """The parameters of ``columns`` whose true value is not negligible: ``|p_i| >=``
    :data:`RELATIVE_FLOOR` × the largest ``|p_j|`` of the same unit among ``columns`` (and
    ``p_i != 0``), in the order of ``columns``."""
    groups = _unit_groups(units, columns)
    scale = {unit: float(np.abs(p_true[group]).max()) for unit, group in groups.items()}
    return [i for i in columns if p_true[i] != 0 and abs(p_true[i]) >= RELATIVE_FLOOR * scale[units[i]]]


# ------------------------------------------------------ few parameters: their curves


def _parameter_label(name: str, true: float, err: np.ndarray, detailed: bool) -> str:
    """Legend entry of ``p̂ − p``: ``p̂_1 − p_1`` in mathtext (letter+digits) or the name."""
    sym = rf"$\hat{{{name[0]}}}_{{{name[1:]}}} - {name[0]}_{{{name[1:]}}}$" if _is_indexed(name) else name
    return f"{sym} (true {true:.3g}; {err[0]:+.3g} → {err[-1]:+.3g})" if detailed else sym


def _line_style(k: int) -> dict[str, str]:
    """Colour and dash of the ``k``-th line: ten colours, then the next dash."""
    return {"color": f"C{k % 10}", "ls": ("-", "--", ":", "-.")[(k // 10) % 4]}


def _legend(ax: Axes, entries: int) -> float:
    """A legend inside ``ax`` for a few entries, else outside on the right; its width [in]."""
    if entries <= INLINE_LEGEND_ENTRIES:
        ax.legend(loc="best", fontsize=8)
        return 0.0
    ncols = math.ceil(entries / LEGEND_ROWS)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, ncols=ncols, borderaxespad=0.0)
    return ncols * (2.9 if entries <= DETAILED_LEGEND_ENTRIES else 1.1)


def _parameter_curves_figure(
    result: SimulationResult,
    columns: Sequence[int],
    kind: str,
    figure_numbers: Mapping[str, int],
    heading: str,
) -> Figure:
    """``p̂ − p`` of the parameters ``columns`` (one panel per unit, a curve each), then
    ``(p̂ − p)/p`` [%] of those whose true value is not negligible (:func:`_relative_columns`)."""
    assert result.p_error is not None and result.p_true is not None
    t = result.t
    p_error, p_true = result.p_error, result.p_true
    names, units = result.parameter_names, result.parameter_units
    groups = _unit_groups(units, columns)
    relative = _relative_columns(p_true, units, columns)
    # Up to ten parameters: one colour each, the same in every panel. More: each panel
    # styles its own lines in order, so the lines of a panel stay apart.
    consistent = len(columns) <= 10
    style = {i: _line_style(k) for k, i in enumerate(columns)}

    rows = len(groups) + (1 if relative else 0)
    fig = new_figure((PARAM_FIGSIZE[0], PARAM_FIGSIZE[1] + PARAM_ROW_HEIGHT * (rows - 1)))
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    legend_width = 0.0
    for ax, (unit, group) in zip(axes, groups.items()):
        ax.set_label(f"absolute [{unit}]")
        detailed = len(group) <= DETAILED_LEGEND_ENTRIES
        for k, i in enumerate(group):
            label = _parameter_label(names[i], float(p_true[i]), p_error[:, i], detailed)
            ax.plot(t, p_error[:, i], lw=1.5, label=label, **(style[i] if consistent else _line_style(k)))
        ax.set_ylabel(f"estimate − true [{unit}]")
        legend_width = max(legend_width, _legend(ax, len(group)))
    if relative:
        ax = axes[-1]
        ax.set_label("relative")
        detailed = len(relative) <= DETAILED_LEGEND_ENTRIES
        for k, i in enumerate(relative):
            rel = 100.0 * p_error[:, i] / p_true[i]
            label = _parameter_symbol(names[i]) + (
                f": {rel[0]:+.0f} % → {rel[-1]:+.0f} %" if detailed else ""
            )
            ax.plot(t, rel, lw=1.3, label=label, **(style[i] if consistent else _line_style(k)))
        ax.set_ylabel("(estimate − true) / true [%]")
        legend_width = max(legend_width, _legend(ax, len(relative)))
    for ax in axes:
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("t [s]")
    axes[-1].set_xlim(t[0], t[-1])
    fig.set_size_inches(PARAM_FIGSIZE[0] + legend_width, fig.get_size_inches()[1])
    what = f"{kind} parameter estimation error p̂ − p"
    fig.suptitle(figure_title(what, PARAMETER_FIGURES[kind], figure_numbers, heading), fontsize=11)
    if legend_width == 0.0:  # every legend inside its panel (an outside one: constrained layout)
        fix_margins(fig, PARAM_MARGINS)
    return fig


# ------------------------------------------------- many parameters: norms and bars


def _short_label(name: str, index: int) -> str:
    """The label of parameter ``index`` (1-based) beside its bar.

    A letter+digits name as itself (``$V_{3}$``); any other as ``β<index>: `` and the
    name's first term, ``+ …`` if it has more (``β4: upper_arm_link.Ixx + …`` for
    ``upper_arm_link.Ixx - 1 upper_arm_link.Izz + 0.1806 forearm_link.m + …``), cut to
    :data:`LABEL_CHARS` characters.
    """
    if _is_indexed(name):
        return _parameter_symbol(name)
    terms = re.split(r" [+-] ", name.strip(), maxsplit=1)
    label = f"β{index}: {terms[0]}" + (" + …" if len(terms) > 1 else "")
    return label if len(label) <= LABEL_CHARS else label[: LABEL_CHARS - 1] + "…"


def _percent(value: float) -> str:
    """A relative error [%], one decimal below 1000 % (``+12.3 %``), two digits above (``+1.7e+03 %``)."""
    return f"{value:+.1f} %" if abs(value) < 999.95 else f"{value:+.2g} %"


def _normalised_errors(
    p_error: np.ndarray, p_true: np.ndarray, groups: Mapping[str, Sequence[int]]
) -> dict[str, np.ndarray]:
    """``‖p̂_g(t) − p_g‖ / ‖p_g‖`` over time of each unit group ``g`` whose true values are
    not all zero (2-norms over the group's parameters), shape (K,) each."""
    return {
        unit: np.linalg.norm(p_error[:, list(group)], axis=1) / float(np.linalg.norm(p_true[list(group)]))
        for unit, group in groups.items()
        if np.any(p_true[list(group)] != 0)
    }


def _parameter_summary_figure(
    result: SimulationResult,
    columns: Sequence[int],
    kind: str,
    figure_numbers: Mapping[str, int],
    heading: str,
) -> Figure:
    """Many parameters at a glance: norms of the error over time, then one bar pair each.

    Panels, top to bottom:

    * ``normalised``: for each unit [u] of the figure whose true values are not all zero,
      ``‖p̂_u(t) − p_u‖ / ‖p_u‖`` (2-norms over that unit's parameters; dimensionless, 0.5
      for an initial guess of half the true values), the start and end values in the legend;
    * ``norm [u]``, for a unit whose true values are all zero (e.g. friction the plant does
      not have): ``‖p̂_u(t) − p_u‖`` [u];
    * ``final [u]``, one per unit: a horizontal bar pair per parameter, ``p̂_i − p_i`` [u]
      at t = 0 (grey, wide) and at the end (blue, narrow), parameters in the result's
      order top to bottom. Left labels: ``β<k>`` (k = the parameter's 1-based index in
      ``result.parameter_names``, where the full name is) with the first term of its name,
      or the name itself if it is a letter and digits (``V3``). Right labels (the twin axes
      ``relative [u]``): the final ``(p̂_i − p_i)/p_i`` [%]; ``p = 0`` where the true value
      is 0 and ``|p| ≈ 0`` where it is below :data:`RELATIVE_FLOOR` × the largest ``|p_j|``
      of that unit (no relative error there).

    The figure is :data:`SUMMARY_WIDTH` wide and grows with the number of parameters
    (:data:`BAR_HEIGHT` each), so no label is cut and no legend leaves the figure.
    """
    assert result.p_error is not None and result.p_true is not None and result.p_hat is not None
    t = result.t
    p_error, p_true = result.p_error, result.p_true
    names, units = result.parameter_names, result.parameter_units
    groups = _unit_groups(units, columns)
    relative = set(_relative_columns(p_true, units, columns))
    normalised = _normalised_errors(p_error, p_true, groups)
    unscaled = [unit for unit in groups if unit not in normalised]
    time_rows = (1 if normalised else 0) + len(unscaled)
    heights = [NORM_PANEL_HEIGHT] * time_rows + [BAR_HEIGHT * len(g) + 0.1 for g in groups.values()]
    fig = new_figure((SUMMARY_WIDTH, sum(heights) + PANEL_DECORATION_HEIGHT * len(heights) + SUPTITLE_HEIGHT))
    axes = list(fig.subplots(len(heights), 1, height_ratios=heights, squeeze=False)[:, 0])
    time_axes, bar_axes = axes[:time_rows], axes[time_rows:]
    end = float(t[-1])

    curves = _norm_panels(time_axes, t, p_error, groups, normalised, unscaled)
    for ax, (unit, group) in zip(bar_axes, groups.items()):
        _bar_panel(ax, unit, group, p_error, p_true, names, relative, end)
    unblock_legends(fig, curves)
    what = f"{kind} parameter estimation error p̂ − p ({len(columns)} parameters)"
    if any(not _is_indexed(names[i]) for i in columns):
        what += "\nβk: the k-th estimated parameter (result.parameter_names[k − 1]), shown by its first term"
    fig.suptitle(figure_title(what, PARAMETER_FIGURES[kind], figure_numbers, heading), fontsize=11)
    return fig


def _norm_panels(
    time_axes: Sequence[Axes],
    t: np.ndarray,
    p_error: np.ndarray,
    groups: dict[str, list[int]],
    normalised: dict[str, np.ndarray],
    unscaled: Sequence[str],
) -> list[tuple[Axes, np.ndarray, np.ndarray]]:
    """The summary's panels over time [s]: the ``normalised`` error of each unit's parameters
    in one, then the error norm [u] of each ``unscaled`` unit; returns their curves (for
    :func:`unblock_legends`)."""
    curves = []
    if normalised:
        ax = time_axes[0]
        ax.set_label("normalised")
        top = 0.0
        for k, (unit, ratio) in enumerate(normalised.items()):
            label = f"[{unit}], {len(groups[unit])} parameters: {ratio[0]:.3g} → {ratio[-1]:.3g}"
            ax.plot(t, ratio, color=f"C{k}", lw=1.5, label=label)
            curves.append((ax, t, ratio))
            top = max(top, float(ratio.max()))
        ax.set_ylim(0.0, 1.45 * top or 1.0)  # head room for the legend
        ax.set_ylabel("‖p̂ − p‖ / ‖p‖")
        ax.set_title("normalised error of each unit's parameters (2-norms over them)", fontsize=9)
    for ax, unit in zip(time_axes[1:] if normalised else time_axes, unscaled):
        ax.set_label(f"norm [{unit}]")
        norm = np.linalg.norm(p_error[:, groups[unit]], axis=1)
        label = f"{len(groups[unit])} parameters [{unit}]: {norm[0]:.3g} → {norm[-1]:.3g}"
        ax.plot(t, norm, color="C2", lw=1.5, label=label)
        curves.append((ax, t, norm))
        ax.set_ylim(0.0, 1.45 * float(norm.max()) or 1.0)
        ax.set_ylabel(f"‖p̂ − p‖ [{unit}]")
        ax.set_title(f"error norm of the [{unit}] parameters (true values all 0)", fontsize=9)
    for ax in time_axes:
        if ax is not time_axes[0]:
            ax.sharex(time_axes[0])
        ax.set_xlim(t[0], t[-1])
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    if time_axes:
        time_axes[-1].set_xlabel("t [s]")
    return curves


def _bar_panel(
    ax: Axes,
    unit: str,
    group: Sequence[int],
    p_error: np.ndarray,
    p_true: np.ndarray,
    names: Sequence[str],
    relative: set[int],
    end: float,
) -> None:
    """One unit's bars: ``p̂_i − p_i`` [unit] at t = 0 and at ``end`` [s] per parameter of
    ``group``, with the final relative error [%] (of the ``relative`` columns) on a twin axis."""
    ax.set_label(f"final [{unit}]")
    y = np.arange(len(group))
    ax.barh(y, p_error[0, group], height=0.8, color=INITIAL_COLOR, label="t = 0")
    ax.barh(y, p_error[-1, group], height=0.42, color=ACTUAL_COLOR, label=f"t = {end:g} s")
    ax.set_yticks(y, [_short_label(names[i], i + 1) for i in group], fontsize=7)
    ax.set_ylim(len(group) - 0.5, -0.5)  # the first parameter on top
    ax.axvline(0.0, color="0.3", lw=0.8)
    ax.grid(True, axis="x", alpha=0.3)
    ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4))
    ax.set_xlabel(f"p̂ − p [{unit}]", fontsize=9)
    ax.set_title(
        f"{len(group)} parameters [{unit}]: error at t = 0 (grey) and at t = {end:g} s (blue)",
        fontsize=9,
    )
    twin = ax.twinx()
    twin.set_label(f"relative [{unit}]")
    twin.set_ylim(ax.get_ylim())
    texts = [
        _percent(100.0 * p_error[-1, i] / p_true[i])
        if i in relative
        else "p = 0"
        if p_true[i] == 0
        else "|p| ≈ 0"
        for i in group
    ]
    twin.set_yticks(y, texts, fontsize=7)
    twin.set_ylabel(f"(p̂ − p) / p at t = {end:g} s", fontsize=8)


# ------------------------------------------------------------------------ a run


def parameter_figures(
    result: SimulationResult, figure_numbers: Mapping[str, int], heading: str
) -> dict[str, Figure]:
    """The parameter figures of a run with estimates: key → figure, ``param_error`` for the
    ``"inertial"`` parameters and ``friction_error`` for the ``"friction"`` ones, each only
    when it has a parameter; more than :data:`MANY_PARAMETERS` in a figure get
    :func:`_parameter_summary_figure`, fewer :func:`_parameter_curves_figure`.

    Raises:
        InvalidParameterError: the result lacks a name, unit or known kind for a parameter.
    """
    check_parameters(result)
    figures: dict[str, Figure] = {}
    for kind in PARAMETER_KINDS:
        columns = [i for i, k in enumerate(result.parameter_kinds) if k == kind]
        if columns:
            build = _parameter_summary_figure if len(columns) > MANY_PARAMETERS else _parameter_curves_figure
            figures[PARAMETER_FIGURES[kind]] = build(result, columns, kind, figure_numbers, heading)
    return figures
