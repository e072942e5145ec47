"""A wrench's window is shaded on the time axes of a run's figures (issue 28 §3): the joint,
torque and task-error figures of ``simulate --plot`` and ``compare``, and nowhere without a
wrench."""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pytest
from matplotlib.patches import Rectangle

from twolink_pin.cli import main
from twolink_pin.plotting import _save


class Axis(NamedTuple):
    """What a saved figure's axis showed (read before the figure is freed)."""

    xlim: tuple[float, float]
    spans: list[tuple[float, float]]
    texts: list[str]
    top: bool


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> dict[str, list[Axis]]:
    """Every figure saved, by file name: its axes. No PNG is rendered (no assertion reads one;
    tests/test_plotting.py checks the files)."""
    figures: dict[str, list[Axis]] = {}

    def keep(fig: Any, path: Path) -> Path:
        top = max((ax.get_position().y1 for ax in fig.axes), default=0.0)
        figures[Path(path).name] = [
            Axis(ax.get_xlim(), _spans(ax), [t.get_text() for t in ax.texts], ax.get_position().y1 == top)
            for ax in fig.axes
        ]
        return Path(path)

    monkeypatch.setattr(_save, "save_figure", keep)
    return figures


def _spans(ax: Any) -> list[tuple[float, float]]:
    """The x extents of the shaded spans on ``ax`` (axvspan's patches, in data x)."""
    out = []
    for patch in ax.patches:
        if isinstance(patch, Rectangle) and patch.get_facecolor()[:3] == pytest.approx(
            (0.58, 0.404, 0.741), abs=1e-2
        ):
            x = patch.get_x()
            out.append((round(x, 9), round(x + patch.get_width(), 9)))
    return out


def test_simulate_shades_the_wrench_window_on_every_time_axis(
    tmp_path: Path, drawn: dict[str, list[Axis]]
) -> None:
    argv = [
        "simulate",
        "osc",
        "--duration",
        "0.3",
        "--wrench",
        "5,0,0@0.1:0.2",
        "--plot",
        str(tmp_path / "f"),
    ]
    assert main(argv) == 0
    names = {"osc_theta1.png", "osc_theta2dot.png", "osc_torque.png", "osc_task_error.png"}
    assert names <= drawn.keys()
    for name in names:
        for i, ax in enumerate(drawn[name]):
            lo, hi = ax.xlim
            if hi > 0.1 and lo < 0.2:  # an axis that shows part of the window
                assert ax.spans == [(0.1, 0.2)], (name, i)
        tops = [ax for ax in drawn[name] if ax.top]
        assert "wrench 0.1–0.2 s" in tops[0].texts


def test_without_a_wrench_nothing_is_shaded(tmp_path: Path, drawn: dict[str, list[Axis]]) -> None:
    assert main(["simulate", "osc", "--duration", "0.3", "--plot", str(tmp_path / "f")]) == 0
    assert drawn and all(not ax.spans for axes in drawn.values() for ax in axes)


def test_a_window_beyond_the_run_is_clipped_and_keeps_the_axes(
    tmp_path: Path, drawn: dict[str, list[Axis]]
) -> None:
    argv = ["simulate", "pd", "--duration", "0.3", "--wrench", "5,0,0@0.2:9", "--plot", str(tmp_path / "f")]
    assert main(argv) == 0
    ax = drawn["pd_theta1.png"][-1]
    assert ax.spans == [(0.2, 0.3)]
    np.testing.assert_allclose(ax.xlim[1], 0.3)
