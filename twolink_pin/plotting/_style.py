"""What every figure shares: sizes, resolution, colours, the non-GUI figure with its fixed
margins, and the figure titles.

Figures are :class:`matplotlib.figure.Figure` objects with their own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg` (never ``pyplot``): no GUI
backend is selected, no global registry holds a figure, and a figure is freed as soon as
it is no longer referenced. Rendering and writing a figure: :mod:`._save`; the helpers that
draw on a panel (limit lines, notes, legends, log labels): :mod:`._panels`. Sizes [in],
resolution [dots per inch].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from twolink_pin.errors import InvalidParameterError


@dataclass(frozen=True)
class Margins:
    """Fixed room around and between a figure's panels [in], set once per figure type instead
    of a layout engine (constrained layout measures every tick label of every panel, twice,
    on each save: half of a figure's CPU time).

    Attributes:
        left, right, bottom, top: Room between the panels and the figure's edges [in]
            (tick labels, axis labels, the suptitle).
        wspace, hspace: Room between neighbouring columns and rows [in].
    """

    left: float
    right: float
    bottom: float
    top: float
    wspace: float = 0.0
    hspace: float = 0.0


DPI = 110
"""Resolution of every saved figure [dots per inch]."""
JOINT_FIGSIZE = (8.0, 8.0)
"""Size of a trajectory joint figure (four stacked panels) [in]."""
WORKSPACE_FIGSIZE = (12.0, 5.5)
"""Size of the workspace figure (full view and zoom on the path) [in]."""
TORQUE_FIGSIZE = (8.0, 6.0)
"""Size of the desired-torque figure of a two-joint arm [in]; see :data:`TORQUE_ROW_HEIGHT`."""
TORQUE_ROW_HEIGHT = 2.7
"""Height each further (or fewer) joint adds to (takes from) a torque figure [in]."""
STATE_FIGSIZE = (8.0, 7.5)
"""Size of a simulation state figure (actual/desired, error, log |error|) [in]."""
SIM_TORQUE_FIGSIZE = (12.0, 6.5)
"""Size of a simulation torque figure of a two-joint arm (whole run and last period) [in]."""
PARAM_FIGSIZE = (8.0, 5.0)
"""Size of a parameter-error figure with one panel and a legend inside it [in]."""
PARAM_ROW_HEIGHT = 2.2
"""Height each further panel adds to a parameter-error figure [in]."""
SUMMARY_WIDTH = 10.0
"""Width of a parameter-error figure of many parameters (norms over time, bars) [in]."""
NORM_PANEL_HEIGHT = 2.2
"""Height of a panel of error norms over time in a many-parameter figure [in]."""
BAR_HEIGHT = 0.2
"""Height each parameter's bar pair takes in a many-parameter figure [in]."""
PANEL_DECORATION_HEIGHT = 0.85
"""Height of a panel's title, tick labels and x label, beside its drawing area [in]."""
SUPTITLE_HEIGHT = 0.75
"""Height of a figure's (two- or three-line) title [in]."""
WORKSPACE_3D_FIGSIZE = (16.0, 5.8)
"""Size of the workspace figure of an arm moving in 3-D (a 3-D view, two projections) [in]."""

STATE_MARGINS = Margins(left=0.9, right=0.15, bottom=0.5, top=0.58, wspace=0.85, hspace=0.55)
"""A run's state figure: a two-line suptitle; between rows a panel title above, tick labels
and an x label below; the late-error panel's tick labels between the columns."""
SIM_TORQUE_MARGINS = Margins(left=0.8, right=0.22, bottom=0.5, top=0.75, wspace=0.75, hspace=0.25)
"""A run's torque figure: a two-line suptitle and the column titles above."""
JOINT_MARGINS = Margins(left=0.92, right=0.18, bottom=0.5, top=0.36, hspace=0.16)
"""A trajectory joint figure: one suptitle line, four panels sharing t."""
TORQUE_MARGINS = Margins(left=0.8, right=0.18, bottom=0.5, top=0.36, hspace=0.2)
"""The desired-torque figure: one suptitle line, a panel per joint sharing t."""
PARAM_MARGINS = Margins(left=0.95, right=0.15, bottom=0.5, top=0.6, hspace=0.2)
"""A parameter-error figure with its legends inside the panels: a two-line suptitle."""

LOG_FLOOR = 1e-16
"""Smallest value shown on a log-scale error panel (exact zeros are drawn there)."""

ACTUAL_COLOR = "tab:blue"
DESIRED_COLOR = "black"
ERROR_COLOR = "tab:red"
LIMIT_COLOR = "tab:red"
COMMAND_COLOR = "tab:orange"
REACH_COLOR = "tab:green"


# ---------------------------------------------------------------------- figures


def new_figure(figsize: tuple[float, float]) -> Figure:
    """A non-GUI figure with its own Agg canvas and constrained layout (a figure type with
    fixed :class:`Margins` replaces it with :func:`fix_margins` once its panels exist)."""
    fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def fix_margins(fig: Figure, margins: Margins) -> None:
    """Place the panels of ``fig`` (one grid) with ``margins`` [in] instead of constrained
    layout. :func:`~twolink_pin.plotting._save.save_figure` checks after drawing that the tick and axis labels fit and falls
    back to constrained layout when they do not (an unusually long tick label)."""
    width, height = fig.get_size_inches()
    spec = fig.axes[0].get_subplotspec()
    assert spec is not None  # every fixed-margin figure is a grid of subplots
    rows, cols = spec.get_gridspec().get_geometry()
    panel_w = (width - margins.left - margins.right - (cols - 1) * margins.wspace) / cols
    panel_h = (height - margins.bottom - margins.top - (rows - 1) * margins.hspace) / rows
    fig.set_layout_engine(None)
    fig.subplots_adjust(
        left=margins.left / width,
        right=1.0 - margins.right / width,
        bottom=margins.bottom / height,
        top=1.0 - margins.top / height,
        wspace=margins.wspace / panel_w,
        hspace=margins.hspace / panel_h,
    )
    fig._twolink_margins = margins  # type: ignore[attr-defined]  # read by save_figure


def rows_figsize(base: tuple[float, float], rows: int, row_height: float) -> tuple[float, float]:
    """``base`` (the size for two rows) grown or shrunk by ``row_height`` per row [in]."""
    return (base[0], base[1] + row_height * (rows - 2))


# ---------------------------------------------------------------------------- titles


def check_figure_numbers(figure_numbers: Mapping[str, int] | None) -> Mapping[str, int]:
    """``figure_numbers`` or an empty mapping; each value a positive integer.

    Raises:
        InvalidParameterError: not a mapping of figure key → positive integer.
    """
    if figure_numbers is None:
        return {}
    if not isinstance(figure_numbers, Mapping):
        raise InvalidParameterError(
            "figure_numbers", figure_numbers, "a mapping figure key → report figure number, or None"
        )
    for key, number in figure_numbers.items():
        if not isinstance(key, str) or isinstance(number, bool) or not isinstance(number, int) or number < 1:
            raise InvalidParameterError(
                f"figure_numbers[{key!r}]", number, "a positive integer (the report's figure number)"
            )
    return figure_numbers


def figure_title(what: str, key: str, figure_numbers: Mapping[str, int], heading: str | None = None) -> str:
    """A figure title: ``heading`` on its own line (if any), then ``what``.

    When ``figure_numbers`` has ``key``, "— cf. report Fig. N" ends the first line.
    """
    number = figure_numbers.get(key)
    cite = f" — cf. report Fig. {number}" if number is not None else ""
    return f"{heading}{cite}\n{what}" if heading else f"{what}{cite}"
