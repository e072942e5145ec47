"""The one writer: atomic files that replace only regular files, output folders staged and
swapped in, never over a user's folder, and input files that are regular and bounded."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from twolink_pin.errors import InputFileError, OutputError
from twolink_pin.files import atomic_write, check_input_file, output_directory, write_json


def test_a_failure_midway_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError), atomic_write(target) as f:
        f.write("new, half")
        raise RuntimeError("boom")
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_a_written_file_gets_the_umasks_permissions(tmp_path: Path) -> None:
    """Not mkstemp's 0600: 0666 minus the umask, like any file the user writes."""
    old = os.umask(0o022)
    try:
        with atomic_write(tmp_path / "a.txt") as f:
            f.write("x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a.txt").stat().st_mode) == 0o644


@pytest.mark.parametrize("target", ["/dev/null", "/dev/full"])
def test_a_device_is_never_replaced(target: str) -> None:
    """Writing "to" a device would rename the temporary over the device node: refused."""
    before = os.stat(target)
    with pytest.raises(OutputError, match="is not a regular file"), atomic_write(target) as f:
        f.write("x")
    after = os.stat(target)
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev


def test_a_fifo_is_refused_as_output_and_as_input(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="not a regular file"), atomic_write(fifo) as f:
        f.write("x")
    with pytest.raises(InputFileError, match="not a regular file"):
        check_input_file(fifo, 100, "a URDF file")
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_a_directory_or_a_file_in_the_way_is_named(tmp_path: Path) -> None:
    with (
        pytest.raises(OutputError, match="is a directory; expected a file path"),
        atomic_write(tmp_path) as f,
    ):
        f.write("x")
    (tmp_path / "file").write_text("")
    with (
        pytest.raises(OutputError, match="exists and is not a directory"),
        atomic_write(tmp_path / "file" / "a.txt") as f,
    ):
        f.write("x")


def test_nan_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    with pytest.raises(ValueError):
        write_json(tmp_path / "x.json", {"a": float("nan")})
    assert not (tmp_path / "x.json").exists()


def test_an_output_folder_replaces_only_its_own_kind(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with output_directory(out, ".mine") as stage:
        (stage / "a.txt").write_text("1")
    assert (out / "a.txt").read_text() == "1" and (out / ".mine").is_file()
    with output_directory(out, ".mine") as stage:  # ours: replaced as a whole
        (stage / "b.txt").write_text("2")
    assert sorted(p.name for p in out.iterdir()) == [".mine", "b.txt"]
    user = tmp_path / "user"
    user.mkdir()
    (user / "thesis.tex").write_text("precious")
    with pytest.raises(OutputError, match="refusing to overwrite"), output_directory(user, ".mine"):
        pass
    assert (user / "thesis.tex").read_text() == "precious"


def test_an_interrupted_folder_leaves_the_previous_one(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with output_directory(out, ".mine") as stage:
        (stage / "a.txt").write_text("1")
    with pytest.raises(KeyboardInterrupt), output_directory(out, ".mine") as stage:
        (stage / "half.txt").write_text("…")
        raise KeyboardInterrupt
    assert sorted(p.name for p in out.iterdir()) == [".mine", "a.txt"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging folder left


def test_an_input_file_must_be_regular_and_bounded(tmp_path: Path) -> None:
    big = tmp_path / "big.urdf"
    big.write_bytes(b"x" * 101)
    with pytest.raises(
        InputFileError, match="is 101 bytes, more than the 100 bytes accepted for a URDF file"
    ):
        check_input_file(big, 100, "a URDF file")
    with pytest.raises(InputFileError, match="file not found"):
        check_input_file(tmp_path / "absent", 100, "a URDF file")
    with pytest.raises(InputFileError, match="is not a regular file"):
        check_input_file("/dev/zero", 100, "a URDF file")
