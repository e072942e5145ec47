"""The tuner's metrics table: this run beside the previous one, the defaults' and a kept run,
as a compact HTML table for the results panel (about 440 px wide).

Each number has three significant digits (the digits a change of a gain moves); a cell of a
run with up to :data:`WIDE` joints lists every joint, one a line (its text reads
``0.014, 0.00121``); beyond, the largest joint's value and which joint (``0.012 (j4)``). A number of this run that reads otherwise than the previous run's is
coloured: green when smaller (an error or a torque went down), red when larger. The kept
run's column is headed ``kept``; its name (as ``compare`` names the variant) is the line
under the table. ``tune --json`` prints every digit of every joint."""

from __future__ import annotations

import html
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.tuning.outcomes import Finished

WIDE = 3
"""A run with more joints than this shows, per metric, its largest joint (the panel is narrow)."""
KEPT = "kept"
"""The kept run's column header (its name is the line under the table)."""
LOWER, HIGHER = "#2b8a3e", "#c92a2a"
"""The colours of a number of this run below and above the previous run's."""
STYLE = (
    "width:100%;border-collapse:collapse;font-size:0.8rem;line-height:1.3;"
    "font-variant-numeric:tabular-nums;table-layout:fixed"
)
CELL = "padding:2px 4px;vertical-align:top;border-bottom:1px solid #e9ecef;overflow-wrap:anywhere"


def _numbers(value: Any) -> list[tuple[str, float]]:
    """A metric's value as the numbers a cell shows: (text, the number compared)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return [(f"{float(array):.3g}", float(array))]
    if array.size <= WIDE:
        return [(f"{x:.3g}", float(x)) for x in array]
    j = int(np.nanargmax(np.abs(array)))
    return [(f"{array[j]:.3g} (j{j + 1})", float(array[j]))]


def _cell(numbers: list[tuple[str, float]], previous: list[tuple[str, float]] | None) -> str:
    """One number a line (a joint's); the ", " between them is in the text (a test or a copy
    reads ``0.014, 0.00121``) but not drawn."""
    parts = []
    for i, (text, x) in enumerate(numbers):
        style = "display:block;white-space:nowrap"
        if previous is not None and i < len(previous) and previous[i][0] != text:
            style += f";color:{LOWER if abs(x) < abs(previous[i][1]) else HIGHER}"
        comma = '<span style="font-size:0">, </span>' if i + 1 < len(numbers) else ""
        parts.append(f'<span style="{style}">{html.escape(text)}{comma}</span>')
    return "".join(parts)


def rows_of(this: Finished) -> list[tuple[str, Callable[[Finished], Any]]]:
    """The table's rows for a run like ``this``: label → the metric of a run."""

    def m(kind: str, name: str) -> Callable[[Finished], Any]:
        return lambda d: getattr(getattr(d.metrics, kind), name)

    rows: list[tuple[str, Callable[[Finished], Any]]] = [
        ("RMS e [rad]", m("rms", "e")),
        ("max |e| [rad]", m("max", "e")),
        ("last period max |e| [rad]", lambda d: d.metrics.final_period_max_abs_e),
        ("RMS τ [N·m]", m("rms", "tau")),
        ("max |τ| [N·m]", m("max", "tau")),
    ]
    if this.task is not None:
        rows += [
            ("task RMS |p − p_d| [mm]", lambda d: d.task.position_rms_mm if d.task else float("nan")),
            ("task RMS angle [deg]", lambda d: d.task.orientation_rms_deg if d.task else float("nan")),
        ]
    return rows


def metrics_table(this: Finished, columns: Mapping[str, Finished | None], heading: str = "") -> str:
    """The metrics of this run beside other runs (column name → run; None: "–"), as HTML:
    a ``previous`` column colours this run's numbers that differ from it; a column of any
    other name than ``previous`` and ``defaults`` is the kept run, headed :data:`KEPT`, its
    name under the table. ``heading``: a line above it (plain text)."""
    runs = {"this run": this, **columns}
    previous = columns.get("previous")
    headers = [name if name in ("this run", "previous", "defaults") else KEPT for name in runs]
    widths = "34%" if len(runs) > 3 else "40%"
    lines = [f'<table style="{STYLE}"><colgroup><col style="width:{widths}"></colgroup>']
    lines.append(
        "<thead><tr>"
        + f'<th style="{CELL}"></th>'
        + "".join(f'<th style="{CELL};text-align:left">{html.escape(h)}</th>' for h in headers)
        + "</tr></thead><tbody>"
    )
    for label, pick in rows_of(this):
        cells = []
        before = None if previous is None else _numbers(pick(previous))
        for name, run in runs.items():
            if run is None:
                cells.append("–")
                continue
            numbers = _numbers(pick(run))
            cells.append(_cell(numbers, before if name == "this run" else None))
        lines.append(
            f'<tr><th style="{CELL};text-align:left;font-weight:normal;color:#495057">{html.escape(label)}</th>'
            + "".join(f'<td style="{CELL}">{c}</td>' for c in cells)
            + "</tr>"
        )
    lines.append("</tbody></table>")
    notes = []
    kept = [name for name in runs if name not in ("this run", "previous", "defaults")]
    if kept:
        notes.append(f'{KEPT}: <code class="twolink-kept">{html.escape(kept[0])}</code>')
    if this.result.q.shape[1] > WIDE:
        notes.append("largest joint shown (<code>tune --json</code> prints every joint)")
    top = f'<div style="font-size:0.8rem;font-weight:600;margin-bottom:2px">{html.escape(heading)}</div>'
    foot = "".join(f'<div style="font-size:0.75rem;color:#495057;margin-top:2px">{n}</div>' for n in notes)
    return (top if heading else "") + "".join(lines) + foot


__all__ = ["KEPT", "WIDE", "metrics_table", "rows_of"]
