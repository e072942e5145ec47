"""What is wrong with a log is said as such: time in milliseconds, angles in degrees, torques in
another unit, a joint that never moves — each named, before the filter or the sample count
would blame something else. Logs are the twolink's exact motion along its excitation, spoiled
one way at a time."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.errors import InputFileError
from twolink_pin.identification import RunLog, write_log
from twolink_pin.identification.diagnostics import check_log
from twolink_pin.twolink import excitation as twolink_excitation


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


@pytest.fixture(scope="module")
def good(twolink) -> RunLog:
    t = 1e-3 * np.arange(8001)
    s = twolink_excitation.identification_excitation().sample(t)
    data = twolink.model.createData()
    tau = np.array([pin.rnea(twolink.model, data, q, v, a) for q, v, a in zip(s.q, s.v, s.a)])
    return RunLog(t=t, q=s.q, tau=tau, source="arm.csv")


def test_a_good_log_passes(twolink, good) -> None:
    check_log(good, twolink)


def test_time_in_milliseconds_is_named(twolink, good) -> None:
    with pytest.raises(
        InputFileError, match=r"median time step 1 s .*time looks like milliseconds \(read as ms: 1000 Hz\)"
    ):
        check_log(replace(good, t=good.t * 1e3), twolink)


def test_angles_in_degrees_are_named(twolink, good) -> None:
    with pytest.raises(
        InputFileError,
        match=r"joint 'joint\d' \(q\d\) spans .* rad, beyond its .*: the angles look like degrees",
    ):
        check_log(replace(good, q=np.degrees(good.q)), twolink)


def test_angles_beyond_the_limits_but_not_degrees(twolink, good) -> None:
    q = good.q.copy()
    q[100:, 1] += 1e4  # a wrapped encoder, not a unit
    with pytest.raises(InputFileError, match=r"joint 'joint2' \(q2\) spans .* beyond its") as info:
        check_log(replace(good, q=q), twolink)
    assert "degrees" not in str(info.value)


def test_torques_in_another_unit_are_named(twolink, good) -> None:
    limit = float(twolink.torque_limits[0])
    with pytest.raises(
        InputFileError,
        match=rf"joint 'joint1' \(tau1\) reaches .* its effort limit {limit:g} N·m: the torques look like another unit",
    ):
        check_log(replace(good, tau=good.tau * 1e3), twolink)


def test_a_joint_that_never_moves_is_named(
    twolink, good, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    q = good.q.copy()
    q[:, 1] = 0.3
    still = replace(good, q=q)
    with pytest.raises(InputFileError, match=r"joint 'joint2' \(q2\) never moves .*twolink-pin excite"):
        check_log(still, twolink)
    path = write_log(tmp_path / "still.csv", still)
    assert main(["identify", "--data", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "joint 'joint2' (q2) never moves" in err[0] and "longer run" not in err[0]
