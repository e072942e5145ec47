"""A sweep that draws the wrench (``--wrench-scale LO:HI`` on ``--wrench``): each run of the
batch equals a single run (the other engine path) pushed by its own drawn wrench; the draws
before it are those of the same study without it; bad input is one line and exit 2."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main

WRENCH = (0.0, -20.0, 0.0)
BASE = ["--duration", "0.5", "--wrench", "0,-20,0@0.1:0.4"]


def _rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "runs.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_each_run_feels_its_drawn_wrench(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    argv = ["sweep", "pd", "--samples", "3", "--q0-spread", "0.02", *BASE, "--wrench-scale", "0:2"]
    assert main([*argv, "--out", str(out)]) == 0
    capsys.readouterr()
    rows = _rows(out)
    scales = np.array([float(r["wrench_scale"]) for r in rows])
    assert np.all((scales >= 0) & (scales <= 2)) and np.ptp(scales) > 0.1
    for r, s in zip(rows, scales, strict=True):
        q0 = [r["q0_offset1"], r["q0_offset2"]]
        force = ",".join(repr(float(s * f)) for f in WRENCH)
        single = ["simulate", "pd", "--duration", "0.5", "--wrench", f"{force}@0.1:0.4", "--q0-offset", *q0]
        assert main([*single, "--json"]) == 0
        metrics = json.loads(capsys.readouterr().out)["metrics"]
        for j in (1, 2):
            assert float(r[f"rms_e{j}"]) == pytest.approx(metrics["rms"]["e"][j - 1], rel=1e-9, abs=1e-15)
            assert float(r[f"max_tau{j}"]) == pytest.approx(metrics["max"]["tau"][j - 1], rel=1e-9)
    # the push matters: the same study with every factor 0 has other errors
    still = tmp_path / "still"
    assert (
        main(
            [
                "sweep",
                "pd",
                "--samples",
                "3",
                "--q0-spread",
                "0.02",
                *BASE,
                "--wrench-scale",
                "0:0",
                "--out",
                str(still),
            ]
        )
        == 0
    )
    capsys.readouterr()
    quiet = _rows(still)
    assert [r["q0_offset1"] for r in quiet] == [r["q0_offset1"] for r in rows]  # same draws before it
    assert max(abs(float(a["rms_e2"]) - float(b["rms_e2"])) for a, b in zip(rows, quiet, strict=True)) > 1e-6


def test_the_draws_before_it_are_unchanged(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert (
        main(["sweep", "pd", "--samples", "2", "--q0-spread", "0.02", *BASE, "--out", str(tmp_path / "a")])
        == 0
    )
    assert (
        main(
            [
                "sweep",
                "pd",
                "--samples",
                "2",
                "--q0-spread",
                "0.02",
                *BASE,
                "--wrench-scale",
                "1:1",
                "--out",
                str(tmp_path / "b"),
            ]
        )
        == 0
    )
    capsys.readouterr()
    a, b = _rows(tmp_path / "a"), _rows(tmp_path / "b")
    assert "wrench_scale" not in a[0] and [float(r["wrench_scale"]) for r in b] == [1.0, 1.0]
    for ra, rb in zip(a, b, strict=True):
        assert ra["q0_offset1"] == rb["q0_offset1"] and ra["rms_e1"] == rb["rms_e1"]


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--wrench-scale", "2:1"], "LO:HI"),
        (["--wrench-scale", "x"], "LO:HI"),
    ],
)
def test_bad_wrench_scales_are_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, extra: list[str], match: str
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["sweep", "pd", "--samples", "2", *BASE, *extra, "--out", str(tmp_path / "x")])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0]


def test_a_wrench_scale_without_a_wrench_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code = main(
        [
            "sweep",
            "pd",
            "--samples",
            "2",
            "--duration",
            "0.1",
            "--wrench-scale",
            "0:1",
            "--out",
            str(tmp_path / "x"),
        ]
    )
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a wrench to scale (--wrench" in err[0]
    assert not (tmp_path / "x").exists()
