"""A figure file carries its title (what it says it shows), and the report captions its
figures with it: they were bare file names (``pd_theta1.png``). Mathtext, which only
matplotlib draws, becomes plain Unicode in the caption."""

from __future__ import annotations

from pathlib import Path

from twolink_pin.plotting._save import save_figure
from twolink_pin.plotting._style import new_figure
from twolink_pin.plotting.titles import shown_title
from twolink_pin.report.pages import figure_captions


def test_a_saved_figure_carries_its_suptitle_in_plain_text_and_the_captions_read_it(tmp_path: Path) -> None:
    fig = new_figure((4, 3))
    fig.add_subplot().plot([0, 1], [0, 1])
    fig.suptitle("controller pd — cf. report Fig. 7\njoint 1: $\\dot\\theta_{1}$ and $\\hat{p}_{2} - p_{2}$")
    assert shown_title(fig) == "controller pd — cf. report Fig. 7 joint 1: θ̇₁ and p̂₂ - p₂"
    save_figure(fig, tmp_path / "pd_theta1dot.png")
    (tmp_path / "notes.png").write_bytes(b"not a png")  # unreadable: no caption, no failure
    assert figure_captions(tmp_path) == {"pd_theta1dot.png": shown_title(fig)}


def test_a_figure_without_a_suptitle_is_titled_by_its_first_panel() -> None:
    fig = new_figure((4, 3))
    fig.add_subplot().set_title("errors of $e_{1}$")
    assert shown_title(fig) == "errors of e₁"
