"""Where the page shows a run: a panel of its own, docked beside the controls, so that the
metrics and the plots stay in view while a slider moves (the controls scroll in their
column; the results scroll in theirs).

The page, left to right: the 3-D view, the controls (:data:`CONTROLS_WIDTH` px: the gains,
the run, the plant, the playback, the command), the results (:data:`RESULTS_WIDTH` px: the
status line, the metrics table with "keep this run", the plots — the joint errors first).
Viser's panels can be dragged, resized and minimised by the user; the widths here are where
they start."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

CONTROLS_WIDTH = 400
"""Width of the controls' column [px]: a slider's label, track and number box on one row."""
RESULTS_WIDTH = 460
"""Width of the results' column [px]: the table's four columns of two-joint cells."""


class Results:
    """The results panel in ``server``'s page: :attr:`status` (Markdown), :attr:`metrics`
    (the table's HTML), the "keep this run" button (calls ``keep()``), and :attr:`plots`
    (:class:`~twolink_pin.tuning.plots.Plots`)."""

    def __init__(self, server: Any, keep: Callable[[], None]) -> None:
        from twolink_pin.tuning.plots import Plots

        gui = server.gui
        self.panel = gui.add_panel()
        tab = self.panel.add_tab("results")
        with tab:
            self.status = gui.add_markdown("starting…", order=1.0)
            self.metrics = gui.add_html("", order=2.0)
            self.keep = gui.add_button(
                "keep this run",
                hint="pin the run shown as a reference: a column here, grey curves in the plots",
                order=3.0,
            )
        self.keep.on_click(lambda _: keep())
        self.plots = Plots(server, tab)
        self.panel.dock_right()
        self.panel.set_width(RESULTS_WIDTH)
        gui.main_panel.float(x=-8, y=8, width=CONTROLS_WIDTH)


__all__ = ["CONTROLS_WIDTH", "RESULTS_WIDTH", "Results"]
