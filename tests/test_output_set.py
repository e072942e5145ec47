"""One command's files, all or nothing (``files.outputs_together``): staged beside their
targets, moved into place together when the block ends well, none of them (and no staging
leftover, no folder made for them) when it fails; a folder of figures replaces only the files
its marker lists."""

from __future__ import annotations

from pathlib import Path

import pytest

from twolink_pin.errors import OutputError
from twolink_pin.files import (
    FIGURES_MARKER,
    atomic_write,
    commit_outputs,
    outputs_together,
    removed_on_failure,
)


def _write(path: Path, text: str) -> None:
    with atomic_write(path) as f:
        f.write(text)


def test_files_appear_together_at_the_end_and_not_before(tmp_path: Path) -> None:
    with outputs_together():
        _write(tmp_path / "a.txt", "a")
        _write(tmp_path / "new" / "b.txt", "b")
        assert not (tmp_path / "a.txt").exists()  # staged, not in place
        assert len(list(tmp_path.glob(".a.txt.*.tmp"))) == 1
    assert (tmp_path / "a.txt").read_text() == "a" and (tmp_path / "new" / "b.txt").read_text() == "b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "new"]


def test_a_failure_leaves_nothing_not_even_the_folders_made_for_them(tmp_path: Path) -> None:
    (tmp_path / "kept.txt").write_text("before")
    with pytest.raises(RuntimeError), outputs_together():
        _write(tmp_path / "kept.txt", "after")
        _write(tmp_path / "deep" / "er" / "c.txt", "c")
        raise RuntimeError("the --save that failed")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt"]
    assert (tmp_path / "kept.txt").read_text() == "before"


def test_commit_moves_what_is_staged_so_far(tmp_path: Path) -> None:
    with outputs_together():
        _write(tmp_path / "a.txt", "a")
        commit_outputs()
        assert (tmp_path / "a.txt").read_text() == "a"


def test_a_figure_folder_replaces_its_own_figures_and_refuses_a_users_file(tmp_path: Path) -> None:
    figures = tmp_path / "figs"
    with outputs_together(), removed_on_failure(figures):
        _write(figures / "x.png", "1")
    assert (figures / FIGURES_MARKER).read_text().splitlines()[1:] == ["entry: x.png"]
    with outputs_together(), removed_on_failure(figures):
        _write(figures / "x.png", "2")  # listed: ours to replace
    assert (figures / "x.png").read_text() == "2"
    (figures / "y.png").write_text("mine")
    with pytest.raises(OutputError, match=r"y\.png.*not a figure twolink-pin wrote"):
        with outputs_together(), removed_on_failure(figures):
            _write(figures / "x.png", "3")
            _write(figures / "y.png", "3")
    assert (figures / "y.png").read_text() == "mine" and (figures / "x.png").read_text() == "2"
    assert not list(figures.glob(".*.tmp"))
