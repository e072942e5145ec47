"""The tuner's metrics table (``twolink_pin.tuning.table``) as the page shows it: every row a
metric of every run to three digits, this run's numbers coloured against the previous run's
(green lower, red higher, nothing when they read the same), a kept run's column headed "kept"
with its name under the table, and the largest joint of a 7-joint arm."""

from __future__ import annotations

import re
from types import SimpleNamespace
from typing import Any

import numpy as np

from twolink_pin.tuning.table import HIGHER, LOWER, metrics_table


def run(e: list[float], joints: int = 2) -> Any:
    """A finished run as the table reads it: its metrics (RMS e = ``e``, the rest 1.0)."""
    ones = np.ones(joints)
    metrics = SimpleNamespace(
        rms=SimpleNamespace(e=np.array(e), tau=ones),
        max=SimpleNamespace(e=ones, tau=ones),
        final_period_max_abs_e=ones,
    )
    return SimpleNamespace(metrics=metrics, task=None, result=SimpleNamespace(q=np.zeros((3, joints))))


def cells(table: str) -> dict[str, list[str]]:
    """Row name → the text of its cells (tags dropped, as a browser's textContent)."""
    rows = {}
    for row in re.findall(r"<tr>(.*?)</tr>", table):
        texts = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", row)]
        rows[texts[0]] = texts[1:]
    return rows


def test_every_run_is_a_column_and_a_cell_reads_as_its_joints() -> None:
    this, previous = run([0.0140032, 0.00121]), run([0.0150, 0.00121])
    table = metrics_table(this, {"previous": previous, "defaults": None})
    rows = cells(table)
    assert rows[""] == ["this run", "previous", "defaults"]
    assert rows["RMS e [rad]"] == ["0.014, 0.00121", "0.015, 0.00121", "–"]


def test_this_runs_numbers_are_coloured_against_the_previous_runs_as_they_read() -> None:
    """Joint 1 went down (green), joint 2 up (red); a joint whose three digits read the same
    is not coloured (0.0121 and 0.01211: the same to the digits shown)."""
    table = metrics_table(run([0.0140, 0.0130, 0.01211], 3), {"previous": run([0.0150, 0.0120, 0.0121], 3)})
    row = re.search(r"RMS e \[rad\]</th>(.*?)</tr>", table).group(1)
    first = re.search(r"<td[^>]*>(.*?)</td>", row).group(1)
    spans = re.findall(r'<span style="([^"]*)">([0-9.]+)', first)
    assert [(text, LOWER in style, HIGHER in style) for style, text in spans] == [
        ("0.014", True, False),
        ("0.013", False, True),
        ("0.0121", False, False),
    ]


def test_a_kept_run_is_headed_kept_and_named_under_the_table() -> None:
    name = "pd@kp=400.0,300.0"
    table = metrics_table(run([0.01, 0.01]), {"previous": None, "defaults": None, name: run([0.02, 0.02])})
    assert cells(table)[""] == ["this run", "previous", "defaults", "kept"]
    assert re.search(r'<code class="twolink-kept">(.*?)</code>', table).group(1) == name


def test_seven_joints_show_the_largest_and_which() -> None:
    e = [0.001, 0.002, -0.009, 0.003, 0.001, 0.002, 0.001]
    rows = cells(metrics_table(run(e, 7), {}))
    assert rows["RMS e [rad]"] == ["-0.009 (j3)"]
