"""The figure of a law's own state (integrators, filters …), beside the parameter estimates.

:func:`state_figure` draws the entries of ``result.state`` that are not parameter estimates
(those have their own figures, :mod:`twolink_pin.plotting.parameters`): one panel per unit,
each entry a curve over the run, labelled with its declared name.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from twolink_pin.plotting._style import new_figure
from twolink_pin.simulation.result import SimulationResult


def state_figure(result: SimulationResult, heading: str) -> Figure | None:
    """The law's non-estimate state over time, or None when it has none."""
    if result.state is None or len(result.state_names) != result.state.shape[1]:
        return None
    estimates = set(result.parameter_names)
    columns = [i for i, name in enumerate(result.state_names) if name not in estimates]
    if not columns:
        return None
    units = list(dict.fromkeys(result.state_units[i] for i in columns))
    fig = new_figure((8.0, 1.0 + 2.4 * len(units)))
    axes = fig.subplots(len(units), 1, sharex=True, squeeze=False)[:, 0]
    t = np.asarray(result.t)
    for ax, unit in zip(axes, units, strict=True):
        for i in columns:
            if result.state_units[i] == unit:
                ax.plot(t, np.asarray(result.state)[:, i], label=result.state_names[i], lw=1.2)
        ax.set_ylabel(f"state [{unit}]" if unit else "state")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(f"{heading}: the law's state")
    return fig
