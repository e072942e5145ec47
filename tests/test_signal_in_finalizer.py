"""A signal that lands while Python runs a finalizer: the handler's ``Terminated`` (or
``KeyboardInterrupt``) cannot propagate from a ``__del__``, and Python would print it as
"Exception ignored in …" with a traceback under a successful command (seen once in the corpus
case ``interrupt-ik-parsed-sigterm``: exit 0, then the traceback). The CLI drops it; any other
unraisable exception is still reported."""

from __future__ import annotations

import argparse
import gc

import pytest

from twolink_pin import cli
from twolink_pin.interrupts import Terminated


class _Raises:
    def __init__(self, exc: BaseException) -> None:
        self.exc = exc

    def __del__(self) -> None:
        raise self.exc


def _command_that_finalizes(exc: BaseException) -> object:
    def command(args: argparse.Namespace) -> int:
        _Raises(exc)  # collected at once: its __del__ raises inside the command
        gc.collect()
        print("done")
        return 0

    return command


@pytest.mark.parametrize("exc", [Terminated(), KeyboardInterrupt()], ids=["sigterm", "sigint"])
def test_an_interrupt_raised_in_a_finalizer_prints_no_traceback(
    exc: BaseException, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    seen: list[BaseException | None] = []  # what reaches the hook that prints "Exception ignored"
    monkeypatch.setattr("sys.unraisablehook", lambda u: seen.append(u.exc_value))
    monkeypatch.setattr(cli, "_run", lambda args: _command_that_finalizes(exc)(args))
    assert cli.main(["info"]) == 0
    out, err = capsys.readouterr()
    assert out == "done\n"
    assert seen == []
    assert "Traceback" not in err and "Exception ignored" not in err, err


def test_other_unraisable_errors_are_still_reported(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    seen: list[BaseException | None] = []
    monkeypatch.setattr("sys.unraisablehook", lambda u: seen.append(u.exc_value))
    monkeypatch.setattr(cli, "_run", lambda args: _command_that_finalizes(ValueError("a real bug"))(args))
    assert cli.main(["info"]) == 0
    assert [type(e).__name__ for e in seen] == ["ValueError"]
