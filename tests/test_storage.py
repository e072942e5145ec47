"""Saved runs (``simulate --save``, ``animate --from``): what is saved comes back, and a file
that is not a saved run is refused naming the file and what is wrong, before anything large
is unpacked."""

from __future__ import annotations

import io
import re
import zipfile
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from twolink_pin import SimulationConfig, load_robot, make_scenario, simulate
from twolink_pin.errors import InputFileError
from twolink_pin.simulation.storage import MAX_RESULT_VALUES, load_result, save_result
from twolink_pin.trajectory import default_trajectory

ROBOT = load_robot()


@pytest.fixture(scope="module")
def result():
    controller, plant = make_scenario("adaptive", ROBOT)
    return simulate(controller, plant, default_trajectory(ROBOT), SimulationConfig(duration=0.2))


def test_a_saved_run_comes_back_equal(result, tmp_path: Path) -> None:
    back = load_result(save_result(result, tmp_path / "run.npz"))
    for entry in fields(result):
        ours, theirs = getattr(result, entry.name), getattr(back, entry.name)
        if isinstance(ours, np.ndarray):
            np.testing.assert_array_equal(theirs, ours)
        else:
            assert theirs == ours, entry.name


def _npz(path: Path, **arrays: np.ndarray) -> Path:
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"q": np.zeros(10)}, r"its q has shape \(10,\); expected \(\d+, nq\)"),
        ({"t_reversed": True}, "its t is not a finite, strictly increasing"),
        ({"q_nan": True}, r"its q is not finite at t = .* s \(row 3\)"),
        ({"q_short": True}, r"its q has shape \(\d+, 2\); expected \(\d+, nq\): one row per time"),
    ],
)
def test_a_file_whose_arrays_disagree_is_refused_naming_it(
    result, tmp_path: Path, change: dict, message: str
) -> None:
    saved = save_result(result, tmp_path / "good.npz")
    with np.load(saved) as data:
        arrays = {k: data[k] for k in data.files}
    if "q" in change:
        arrays["q"] = change["q"]
    if change.get("t_reversed"):
        arrays["t"] = arrays["t"][::-1].copy()
    if change.get("q_nan"):
        arrays["q"] = arrays["q"].copy()
        arrays["q"][3, 0] = np.nan
    if change.get("q_short"):
        arrays["q"] = arrays["q"][:-1]
    bad = _npz(tmp_path / "bad.npz", **arrays)
    with pytest.raises(InputFileError, match=message) as err:
        load_result(bad)
    assert "bad.npz" in str(err.value)


def test_a_forged_header_is_refused_before_allocating(tmp_path: Path) -> None:
    """An .npy header claiming 10¹² float64 values (8 TB), with 16 bytes of data behind it."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
    forged = tmp_path / "forged.npz"
    with zipfile.ZipFile(forged, "w") as archive:
        archive.writestr("t.npy", b"\x93NUMPY\x01\x00" + header.getvalue()[8:] + b"\0" * 16)
    with pytest.raises(InputFileError, match=re.escape(f"claim more than {MAX_RESULT_VALUES:g} numbers")):
        load_result(forged)


def test_not_a_result_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match=r"not a twolink-pin result: missing \['controller'"):
        load_result(_npz(tmp_path / "other.npz", x=np.zeros(3)))
    (tmp_path / "text.npz").write_text("hello")
    with pytest.raises(InputFileError, match="cannot read a saved simulation result"):
        load_result(tmp_path / "text.npz")
