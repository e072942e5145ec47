"""Tests of twolink_pin.visualization.notebook: the animated scene as a notebook output, an
``<iframe srcdoc>`` holding exactly the page ``write_html`` writes (the browser side, the
scene playing from the saved notebook, is tested in tests/test_tutorial.py)."""

from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot
from twolink_pin.trajectory import default_trajectory
from twolink_pin.visualization import InlineAnimation, inline_animation, write_html

ROBOT = load_robot()
T = np.linspace(0.0, 1.0, 101)
Q_DES = default_trajectory(ROBOT).sample(T).q
Q = Q_DES + 0.05


def _without_commands(page: str) -> str:
    """The page with its base64 scene commands blanked."""
    return re.sub(r'"[A-Za-z0-9+/=]{40,}"', '""', page)


def test_iframe_srcdoc_unescapes_to_the_written_page(tmp_path: Path) -> None:
    """The frame's ``srcdoc`` attribute, HTML-unescaped as the browser does, is the page
    ``write_html`` writes for the same run (``scene_page``); scripts run in a sandbox, and
    the frame has no ``src`` to fetch."""
    animation = inline_animation(ROBOT, T, Q, Q_DES, via_points=[(0.48, 0.1)], height=300)
    frame = animation._repr_html_()
    match = re.fullmatch(r'<iframe ([^>]*?) srcdoc="([^"]*)"></iframe>', frame)
    assert match is not None
    assert 'sandbox="allow-scripts"' in match[1] and "height: 300px" in match[1] and " src=" not in match[1]
    path = write_html(
        ROBOT, T, Q, Q_DES, path=tmp_path / "run.html", via_points=[(0.48, 0.1)], title="arm motion"
    )
    assert html.unescape(match[2]) == animation.page
    written = path.read_text(encoding="utf-8")
    assert len(written) == len(animation.page)  # meshcat's object uuids differ from call to call:
    assert _without_commands(written) == _without_commands(animation.page)  # compare all but the commands
    assert repr(animation) == f"InlineAnimation(height=300, page={len(animation.page)} characters)"
    assert isinstance(animation, InlineAnimation)


@pytest.mark.parametrize("height", [99, 2001, 400.0, True, None])
def test_bad_height_is_rejected(height: object) -> None:
    with pytest.raises(
        InvalidParameterError,
        match=r"height = .* is invalid: expected a whole number of pixels from 100 to 2000",
    ):
        inline_animation(ROBOT, T, Q, height=height)  # type: ignore[arg-type]


def test_bad_arrays_are_rejected_as_by_write_html() -> None:
    with pytest.raises(InvalidParameterError, match=r"q\.shape = \(101, 1\) is invalid"):
        inline_animation(ROBOT, T, Q[:, :1])
