"""The sim-to-sim figure: what each of the arm's effects on MuJoCo changes in each law's tracking.

:func:`save_sim_to_sim_figure` draws, for each row of the report's section "Sim-to-sim"
(:mod:`twolink_pin.report.sim_to_sim`) after the first, each law's differences ``Δ RMS ‖e‖``
and ``Δ max |e|`` [mrad] from the law on the Pinocchio plant, as grouped
horizontal bars on symmetric-log axes (an effect can lower the error as well as raise it;
"no effect" sits at rounding level, inside the linear band around 0). A law without a row (the
report runs each effect alone on its first law by default) has no bar in that group.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import new_figure

LINEAR_BAND = 1e-3
"""The symmetric-log axis is linear within ±this [mrad] (differences at rounding level)."""


PANELS = (("delta_rms_e", "Δ RMS ‖e‖ [mrad]"), ("delta_max_e", "Δ max |e| [mrad]"))
"""The two panels: the row field [rad] and the axis label."""


def save_sim_to_sim_figure(laws: Sequence[Mapping[str, Any]], path: Path, title: str) -> Path:
    """Write the figure (module docstring) of ``laws`` (each ``{"law", "rows": [{"short",
    "finished", "delta_rms_e", "delta_max_e" [rad]}, ...]}``; rows matched by ``short``, in
    the order of the law with the most) to ``path``: one panel per :data:`PANELS` entry, a group
    of bars per row (one per law that has it, in the laws' order, centred on the row's label)."""
    longest: Sequence[Mapping[str, Any]] = max((law["rows"] for law in laws), key=len, default=[])
    labels = [row["short"] for row in longest[1:]]
    count = max(len(laws), 1)
    height = 0.8 / count
    fig = new_figure((11.0, 1.6 + 0.5 * len(labels) * max(count, 3) / 3))
    y = np.arange(len(labels))[::-1].astype(float)
    axes = [fig.add_subplot(1, len(PANELS), k + 1) for k in range(len(PANELS))]
    rows = [{row["short"]: row for row in law["rows"][1:]} for law in laws]
    present = [[i for i, own in enumerate(rows) if label in own] for label in labels]  # per group
    for ax, (field, xlabel) in zip(axes, PANELS):
        for i, law in enumerate(laws):
            shown = [k for k, label in enumerate(labels) if label in rows[i]]
            values = [
                1e3 * row[field] if (row := rows[i][labels[k]]).get("finished") and field in row else np.nan
                for k in shown
            ]
            # the group's bars centred on its label: this law's place among the laws that have the row
            places = [(len(present[k]) - 1 - 2 * present[k].index(i)) * height / 2 for k in shown]
            ax.barh(y[shown] + np.asarray(places), values, height=height, label=law["law"], **_bar_style(i))
        ax.set_xscale("symlog", linthresh=LINEAR_BAND)
        ax.axvline(0.0, color="0.3", lw=0.8)
        ax.set_xlabel(xlabel + ", symmetric log")
        ax.grid(axis="x", alpha=0.3)
    axes[0].set_yticks(y, labels)
    axes[1].set_yticks(y, [""] * len(labels))
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=min(count, 5), fontsize="small")
    fig.suptitle(title)
    return save_figure(fig, path)


def _bar_style(i: int) -> dict[str, Any]:
    """The ``i``-th law's bars: matplotlib's ten cycle colours, hatched from the eleventh law on
    (the UR5's eleven laws: mpc's bars would take pd's colour)."""
    style: dict[str, Any] = {"color": f"C{i % 10}"}
    if i >= 10:
        style |= {"hatch": "///", "edgecolor": "white"}
    return style


__all__ = ["LINEAR_BAND", "PANELS", "save_sim_to_sim_figure"]
