"""Matrix gains as a researcher writes them (issue 28 §6): k² numbers on the command line are a
k × k matrix (row by row), a refusal names the check that failed with the numbers, and matrix
gains print as their rows in the text and the JSON."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.controllers import Controller, Gains, LawInput, LawOutput, gain
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot

RUN = ["simulate", "osc", "--duration", "0.05"]
DIAGONAL = [1500.0, 1500.0, 800.0]
"""``kp=1500,0,0,0,1500,0,0,0,800`` as the results show it: a diagonal matrix as its diagonal."""


def _json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> dict[str, Any]:
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_nine_numbers_are_a_three_by_three_matrix_a_diagonal_one_shown_as_its_diagonal(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """``kp=1500,0,0,0,1500,0,0,0,800`` runs exactly as the diagonal ``kp=1500,1500,800``, and is
    shown as the diagonal (what ``--gain`` takes back)."""
    full = _json(capsys, [*RUN, "--gain", "kp=1500,0,0,0,1500,0,0,0,800"])
    diagonal = _json(capsys, [*RUN, "--gain", "kp=1500,1500,800"])
    assert full["gains"]["kp"] == DIAGONAL and full["gains"]["kd"] == [20.0, 20.0, 20.0]
    assert full["metrics"] == diagonal["metrics"] and full["task_metrics"] == diagonal["task_metrics"]
    assert main([*RUN, "--gain", "kp=1500,0,0,0,1500,0,0,0,800"]) == 0
    text = capsys.readouterr().out
    assert "  gains kp = (1500, 1500, 800) 1/s², kd = (20, 20, 20) 1/s," in text


def test_a_full_matrix_changes_the_run(capsys: pytest.CaptureFixture[str]) -> None:
    """On the UR5 (a 6-D task: every off-diagonal entry acts)."""
    ur5 = ["simulate", "osc", "--robot", "ur5", "--duration", "0.03"]
    coupled = _json(capsys, [*ur5, "--gain", "kp=1500,300,0,300,1500,0,0,0,800"])
    assert coupled["gains"]["kp"] == [[1500.0, 300.0, 0.0], [300.0, 1500.0, 0.0], [0.0, 0.0, 800.0]]
    diagonal = _json(capsys, [*ur5, "--gain", "kp=1500,1500,800"])
    assert coupled["metrics"]["rms"]["e"] != diagonal["metrics"]["rms"]["e"]


@pytest.mark.parametrize(
    ("value", "says"),
    [
        (
            "1500,0,0,1,1500,0,0,0,800",
            "kp = [[1500.0, 0.0, 0.0], [1.0, 1500.0, 0.0], [0.0, 0.0, 800.0]] is invalid: expected a symmetric",
        ),
        (
            "1500,0,0,1,1500,0,0,0,800",
            "the symmetry check failed: it is not symmetric (entry [0, 1] = 0 but [1, 0] = 1)",
        ),
        (
            "1500,0,0,0,-1500,0,0,0,800",
            "the positive-definite check failed: it is not positive definite (eigenvalues -1500, 800, 1500;",
        ),
        (
            "1,2,3,4,5,6,7,8",
            "the shape check failed: 8 numbers are neither 1, 3 (a diagonal) nor 9 (a 3 × 3 matrix",
        ),
        ("1500,-2,800", "the positive-definite check failed: a diagonal entry is not > 0 (smallest -2)"),
    ],
)
def test_a_refusal_names_the_failed_check_and_the_numbers(
    value: str, says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*RUN, "--gain", f"kp={value}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and says in err[0], err


@dataclass(frozen=True, eq=False)
class _JointGains(Gains):
    kp: Any = gain(100.0, per="joint", matrix=True, unit="N·m/rad")


class _JointMatrixLaw(Controller[_JointGains], register=False):
    """τ = −Kp e (a test law with an nv × nv matrix gain)."""

    name = "joint-matrix"
    title = "joint matrix"
    Gains = _JointGains

    def compute(self, x: LawInput, terms: Any) -> LawOutput:
        return LawOutput(-np.matvec(self.gains.kp, x.q - x.q_des))


def test_a_per_joint_matrix_gain_reads_k_squared_numbers_with_the_robots_k() -> None:
    """4 numbers are a 2 × 2 matrix on the twolink; on a 4-joint arm they would be its diagonal,
    so the reading waits for the law's k (and so do its checks); 2 numbers are a diagonal."""
    twolink = load_robot("twolink")
    law = _JointMatrixLaw(twolink, _JointGains(kp=(300.0, 20.0, 20.0, 250.0)))
    np.testing.assert_array_equal(law.gains.kp, [[[300.0, 20.0], [20.0, 250.0]]])
    assert law.gains.describe() == "kp = [[300, 20], [20, 250]] N·m/rad"
    np.testing.assert_array_equal(
        _JointMatrixLaw(twolink, _JointGains(kp=(300.0, 250.0))).gains.kp, [np.diag([300.0, 250.0])]
    )
    with pytest.raises(
        InvalidParameterError, match=r"kp = \[\[300.0, 20.0\], \[21.0, 250.0\]\] .* symmetry check failed"
    ):
        _JointMatrixLaw(twolink, _JointGains(kp=(300.0, 20.0, 21.0, 250.0)))


def test_compare_tables_list_each_laws_gains_as_the_csv_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "cmp"
    argv = ["compare", "pd", "osc", "--duration", "0.05", "--no-plot", "--out", str(out)]
    assert main([*argv, "--gain", "osc.kp=1500,0,0,0,1500,0,0,0,800"]) == 0
    capsys.readouterr()
    kp = "kp = (1500, 1500, 800)"
    markdown = (out / "comparison.md").read_text()
    assert "| pd | kp = (350, 300), kd = (40, 50) | no friction | finished |" in markdown
    assert f"| osc | {kp}, kd = (20, 20, 20)," in markdown
    assert 'pd,"kp = (350, 300), kd = (40, 50)"' in (out / "comparison.csv").read_text()
    assert json.loads((out / "comparison.json").read_text())["gains"]["osc"]["kp"] == DIAGONAL


def test_controllers_says_which_gains_are_matrices(capsys: pytest.CaptureFixture[str]) -> None:
    osc = {c["name"]: c for c in _json(capsys, ["controllers"])["controllers"]}["osc"]
    kp = {g["name"]: g for g in osc["gains"]}["kp"]
    assert kp["matrix"] is True and kp["per"] == "axis"
    assert main(["controllers"]) == 0
    assert "kp [1/s²] (3 × 3 matrix)" in capsys.readouterr().out


def test_numbers_awaiting_k_survive_a_replace() -> None:
    """``dataclasses.replace`` validates every field again (as a law does when it fills a
    derived gain): the k² numbers still wait for k."""
    from dataclasses import replace

    gains = replace(
        _JointGains(kp=(300.0, 20.0, 20.0, 250.0)), kp=_JointGains(kp=(300.0, 20.0, 20.0, 250.0)).kp
    )
    law = _JointMatrixLaw(load_robot("twolink"), gains)
    np.testing.assert_array_equal(law.gains.kp, [[[300.0, 20.0], [20.0, 250.0]]])


def test_a_per_run_scalar_beside_a_matrix_gain_survives_the_matrix_resolution() -> None:
    """A law resolves a matrix gain by replacing it in its gains (dataclasses.replace), which
    validates every field again: a per-run scalar, stored as a column (N, 1), must pass that
    second validation unchanged (it was refused as 'shape (N, 1)': a sweep of such a law failed)."""

    @dataclass(frozen=True, eq=False)
    class MatrixAndScalar(Gains):
        k: Any = gain(2.0, per="joint", matrix=True, unit="N·m/rad")
        w: Any = gain(0.5, bound="fraction")

    class Law(Controller[MatrixAndScalar], register=False):
        name = "test-matrix-and-scalar"
        title = "test"
        Gains = MatrixAndScalar

        def compute(self, x: LawInput, terms: Any) -> LawOutput:
            return LawOutput(np.zeros_like(x.q))

    law = Law(load_robot(), MatrixAndScalar(k=[1.0, 2.0], w=[0.1, 0.2, 0.3]))
    assert law.runs == 3 and law.gains.w.shape == (3, 1)
    np.testing.assert_array_equal(law.gains.w[:, 0], [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(law.gains.k[0], np.diag([1.0, 2.0]))
