"""A law that never returns, with no ``--timeout`` given (the default bound is a day): its run
ends once it has made no progress for ``deadline.STALL`` seconds (600 s; 1 s here) — no call
of the law returned — naming the law; a law file whose import never returns likewise; a slow
law that keeps returning is never taken for a stalled one."""

from __future__ import annotations

from pathlib import Path

import pytest

from twolink_pin.cli import main
from twolink_pin.simulation import deadline

LAWS = Path(__file__).resolve().parent / "corpus" / "laws"
SLOW = """
import time
from twolink_pin.controllers import PDFeedforward

class Slow(PDFeedforward):
    name = "slow-but-alive"

    def compute(self, x, terms):
        time.sleep(0.005)  # 200 times shorter than the stall bound below
        return super().compute(x, terms)
"""


@pytest.fixture
def stall(monkeypatch: pytest.MonkeyPatch) -> float:
    monkeypatch.setattr(deadline, "STALL", 1.0)
    return 1.0


def test_a_law_that_never_returns_ends_its_run_without_a_timeout(
    stall: float, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["simulate", f"{LAWS}/misbehaving.py:Sleeper", "--duration", "0.5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "controller 'corpus-sleeper' failed at t = 0.01 s" in err
    assert "made no progress for 1 s" in err and "Sleeper" in err and "--timeout 0" in err


def test_a_law_file_whose_import_never_returns_is_named_with_its_line(
    stall: float, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["simulate", f"{LAWS}/sleeps_on_import.py:Law", "--duration", "0.5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "did not return within 1 s (no progress" in err and "sleeps_on_import.py:5" in err


def test_a_slow_law_that_keeps_returning_runs_to_its_end(stall: float, tmp_path: Path) -> None:
    """800 calls of 5 ms each (4 s, four stall periods): the alarm sees progress at each look."""
    (tmp_path / "slow.py").write_text(SLOW)
    assert main(["simulate", f"{tmp_path}/slow.py:Slow", "--duration", "0.2", "--json"]) == 0


def test_an_explicit_timeout_shorter_than_the_stall_bound_is_exact(
    stall: float, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--timeout 0.5`` (below the stall bound): the timeout's own message, as before."""
    assert main(["simulate", f"{LAWS}/misbehaving.py:Sleeper", "--duration", "0.5", "--timeout", "0.5"]) == 1
    assert "did not finish within --timeout 0.5 s" in capsys.readouterr().err
