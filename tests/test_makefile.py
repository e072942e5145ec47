"""The Makefile on a machine of someone else's: it reads no plain ``OUT`` from the environment
(``make demo`` wrote the report into whatever folder an exported ``OUT`` named, and ``make
clean`` ran ``rm -rf`` on it), and ``make clean`` removes only what the report wrote into its
folder (``scripts/clean_report.py``: the entries its marker lists)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from twolink_pin.files import MANIFEST_PREFIX
from twolink_pin.report import MARKER

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="needs make")


def _make(*args: str, cwd: Path, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["make", *args], cwd=cwd, env={**os.environ, **env}, capture_output=True, text=True, timeout=120
    )


def test_an_exported_OUT_does_not_move_the_demo(tmp_path: Path) -> None:
    printed = _make("-n", "demo", cwd=ROOT, OUT=str(tmp_path / "theirs")).stdout
    assert "report --out out" in printed and str(tmp_path) not in printed
    named = _make("-n", "demo", "TWOLINK_PIN_DEMO_OUT=elsewhere", cwd=ROOT).stdout
    assert "report --out elsewhere" in named


def _tree(tmp_path: Path) -> Path:
    """A copy of the Makefile and the clean script, a report folder holding a file of the
    user's beside the report's, and the user's folder an exported OUT names."""
    (tmp_path / "scripts").mkdir()
    shutil.copy(ROOT / "Makefile", tmp_path)
    shutil.copy(ROOT / "scripts" / "clean_report.py", tmp_path / "scripts")
    report = tmp_path / "out"
    (report / "figures").mkdir(parents=True)
    (report / "index.html").write_text("<html>")
    (report / "figures" / "a.png").write_bytes(b"png")
    (report / MARKER).write_text(
        "written by twolink-pin report\n"
        + "".join(f"{MANIFEST_PREFIX}{n}\n" for n in ("figures", "index.html"))
    )
    (report / "notes.txt").write_text("mine")
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    (theirs / "thesis.tex").write_text("years of work")
    return tmp_path


def test_make_clean_removes_what_the_report_wrote_and_nothing_else(tmp_path: Path) -> None:
    tree = _tree(tmp_path)
    done = _make("clean", f"PYTHON={sys.executable}", cwd=tree, OUT=str(tree / "theirs"))
    assert done.returncode == 0, done.stderr
    assert (tree / "theirs" / "thesis.tex").read_text() == "years of work"
    assert sorted(p.name for p in (tree / "out").iterdir()) == ["notes.txt"]
    assert "notes.txt" in done.stderr  # said why out/ stays


def test_make_clean_leaves_a_folder_without_the_marker_and_removes_a_whole_report(tmp_path: Path) -> None:
    tree = _tree(tmp_path)
    (tree / "out" / "notes.txt").unlink()
    (tree / "mine").mkdir()
    (tree / "mine" / "index.html").write_text("not a report")
    done = _make("clean", f"PYTHON={sys.executable}", "TWOLINK_PIN_DEMO_OUT=out", cwd=tree)
    assert done.returncode == 0, done.stderr
    assert not (tree / "out").exists()
    done = _make("clean", f"PYTHON={sys.executable}", "TWOLINK_PIN_DEMO_OUT=mine", cwd=tree)
    assert done.returncode == 0 and (tree / "mine" / "index.html").read_text() == "not a report"


def test_the_clean_script_knows_the_reports_marker() -> None:
    text = (ROOT / "scripts" / "clean_report.py").read_text()
    assert f'MARKER = "{MARKER}"' in text and f'ENTRY = "{MANIFEST_PREFIX}"' in text


def test_the_demo_runs_on_compiled_bytecode() -> None:
    """``make demo`` writes the package's bytecode before the report: with PYTHONDONTWRITEBYTECODE
    set, an editable install's processes (the report's workers) would otherwise compile every
    module they import, each time."""
    printed = _make("-n", "demo", cwd=ROOT).stdout.splitlines()
    compiled = [i for i, line in enumerate(printed) if "-m compileall -q twolink_pin" in line]
    report = [i for i, line in enumerate(printed) if "twolink-pin report" in line]
    assert compiled and report and compiled[0] < report[0]
