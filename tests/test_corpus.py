"""The bad-input corpus (``tests/corpus/``): every hostile input gives its expected outcome.

Each command-line case runs in a fresh folder (its working directory) and must meet its own
expectations (exit status, words on stderr, files present, absent or unchanged) and the
invariants of every case (``tests/corpus/runner.py``): no traceback, no hang, one line on
stderr for an error, no nan/inf from a success, no partial or replaced file, no process
left behind. Library cases call the public functions with wrong sizes, NaN and wrong types:
each must raise :class:`~twolink_pin.errors.InvalidParameterError` (or the error named)
naming the argument.

Set ``TWOLINK_CORPUS_LOG=path.jsonl`` to get one JSON line per case (outcome and problems).
"""

from __future__ import annotations

import json
import os
import signal
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from corpus import runner
from corpus.cases import CASES, LIBRARY
from corpus.cases_equations import EQUATIONS
from corpus.cases_joint_limits import JOINT_LIMITS
from corpus.cases_limits import LIMITS, LIMITS_LIBRARY
from corpus.cases_mpc import MPC
from corpus.cases_optimal import OPTIMAL, OPTIMAL_LIBRARY
from corpus.cases_round5 import ROUND5
from corpus.cases_tune import TUNE_CASES
from corpus.cases_variants import GAINS, GAINS_LIBRARY
from corpus.spec import URDF, Case, LibCase


def _log(case_id: str, cls: str, record: dict[str, Any]) -> None:
    path = os.environ.get("TWOLINK_CORPUS_LOG")
    if path:
        with open(path, "a", encoding="utf-8") as f:
            f.write(json.dumps({"id": case_id, "class": cls, **record}) + "\n")


def _describe(case: Case, outcome: runner.Outcome, problems: list[str]) -> str:
    lines = [
        f"{case.id}: twolink-pin {' '.join(map(str, case.argv))}",
        f"  exit {outcome.code} after {outcome.seconds:.1f} s (expected {case.exit}); "
        f"stderr ends {runner.last_line(outcome.stderr)[:300]!r}",
    ]
    if case.note:
        lines.append(f"  note: {case.note}")
    lines += [f"  - {p}" for p in problems]
    return "\n".join(lines)


@pytest.fixture(scope="module", autouse=True)
def _registry() -> Any:
    """Forget the corpus's own laws afterwards: in-process cases register them."""
    from twolink_pin.controllers import CONTROLLERS

    before, modules = dict(CONTROLLERS), set(sys.modules)
    yield
    CONTROLLERS.clear()
    CONTROLLERS.update(before)
    for name in set(sys.modules) - modules:
        if name.startswith("twolink_pin_user_"):
            del sys.modules[name]


ALL_CASES = [*CASES, *LIMITS, *JOINT_LIMITS, *GAINS, *OPTIMAL, *MPC, *TUNE_CASES, *EQUATIONS, *ROUND5]
ALL_LIBRARY = [*LIBRARY, *LIMITS_LIBRARY, *GAINS_LIBRARY, *OPTIMAL_LIBRARY]


@pytest.mark.parametrize("case", ALL_CASES, ids=[c.id for c in ALL_CASES])
def test_command_line(case: Case, tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """The case's expected outcome, and every invariant (see tests/corpus/runner.py)."""
    reason = runner.unavailable(case.run)
    if reason:
        pytest.skip(reason)
    ctx = runner.prepare(case, tmp_path, capfd)
    try:
        before = runner.snapshot(ctx.folder)
        outcome = runner.run(case, ctx, capfd)
        problems = runner.verify(case, ctx, before, outcome)
    finally:
        ctx.close()
    _log(
        case.id,
        case.cls,
        {
            "exit": outcome.code,
            "expected": case.exit,
            "seconds": round(outcome.seconds, 2),
            "stderr": runner.last_line(outcome.stderr)[:400],
            "problems": problems,
        },
    )
    runner.cleanup(tmp_path)  # some cases write hundreds of MB; the message says what happened
    assert not problems, _describe(case, outcome, problems)


@pytest.fixture(scope="module")
def scope() -> dict[str, Any]:
    """What a library case's expression sees."""
    import twolink_pin as tp
    from twolink_pin import dynamics, kinematics
    from twolink_pin.simulation import SimulationConfig

    robot = tp.load_robot()
    controller, plant = tp.make_scenario("pd", robot)
    return {
        "np": np,
        "tp": tp,
        "dynamics": dynamics,
        "kinematics": kinematics,
        "robot": robot,
        "model": robot.model,
        "data": robot.create_data(),
        "plant": plant,
        "controller": controller,
        "trajectory": tp.default_trajectory(robot),
        "SimulationConfig": SimulationConfig,
        "Path": Path,
        "URDF": URDF,
    }


class _Timeout(BaseException):
    pass


def _alarm(signum: int, frame: object) -> None:
    raise _Timeout


def _summary(value: Any) -> str:
    if isinstance(value, np.ndarray):
        nan = " with NaN" if value.dtype.kind == "f" and np.isnan(value).any() else ""
        return f"an array of shape {value.shape}{nan}"
    return f"{type(value).__name__} {str(value)[:80]!r}"


@pytest.mark.parametrize("case", ALL_LIBRARY, ids=[c.id for c in ALL_LIBRARY])
def test_library(case: LibCase, scope: dict[str, Any]) -> None:
    """The call raises the error named (InvalidParameterError by default), naming the argument."""
    import twolink_pin.errors as errors

    expected = tuple(getattr(errors, name) for name in case.exc.split("|"))
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, 30.0)
    problem = None
    message = ""
    try:
        value = eval(case.expr, dict(scope))
        problem = f"returned {_summary(value)} instead of raising {case.exc}"
    except _Timeout:
        problem = "hang: no answer within 30 s"
    except expected as exc:
        message = str(exc)
        missing = [w for w in case.words if not any(a.lower() in message.lower() for a in w.split("|"))]
        if missing:
            problem = f"{type(exc).__name__} lacks {missing}: {message[:300]!r}"
    except BaseException as exc:
        message = f"{type(exc).__name__}: {exc}"
        problem = f"raised {message[:300]} instead of {case.exc}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    _log(case.id, "library", {"problems": [problem] if problem else [], "message": message[:400]})
    assert problem is None, f"{case.id}: {case.expr}\n  - {problem}"
