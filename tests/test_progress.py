"""Progress bars only on a terminal: a log, a pipe or a notebook stays clean (issue 28 §9)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from twolink_pin.cli import main

COMPARE = ["compare", "pd", "pd-gravity", "--duration", "0.05", "--no-plot"]


def test_compare_into_a_log_prints_no_progress_bar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """stderr captured (not a terminal): nothing but what the command says, no tqdm bar."""
    assert main([*COMPARE, "--out", str(tmp_path / "cmp")]) == 0
    err = capsys.readouterr().err
    assert "run/s" not in err and "2/2" not in err and "%|" not in err, err


def test_compare_on_a_terminal_shows_its_bar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    assert main([*COMPARE, "--out", str(tmp_path / "cmp")]) == 0
    err = capsys.readouterr().err
    assert "compare" in err and "2/2" in err, err
