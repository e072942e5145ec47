"""The console script's entry (``twolink_pin_entry``): handlers before the heavy import, and
the stage markers the corpus's interrupt cases wait for (instead of a fixed delay)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_console_script_is_the_light_entry() -> None:
    """pyproject's script points at the entry, and importing it loads no part of the package
    (so the handlers are in place before Pinocchio and NumPy load)."""
    from importlib.metadata import entry_points

    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "twolink-pin"]
    assert script.value == "twolink_pin_entry:main"
    probe = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys, twolink_pin_entry; print(sorted(m for m in sys.modules if m.startswith(('twolink_pin.', 'numpy'))) or 'none')",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert probe.stdout.strip() == "none"


def test_stages_are_reported_in_order(tmp_path: Path) -> None:
    """TWOLINK_PIN_READY_FILE receives started, parsed, running (and writing when a file is
    written), in that order; the command's answer is unchanged."""
    ready = tmp_path / "ready"
    env = {"TWOLINK_PIN_READY_FILE": str(ready), "PATH": "/usr/bin:/bin"}
    proc = subprocess.run(
        [sys.executable, "-m", "twolink_pin_entry", "fk", "0", "0", "--json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["xy"] == [0.62, 0.0]  # l1 + l2 at q = 0, exactly
    assert ready.read_text().split() == ["started", "parsed", "running"]
    ready.unlink()
    proc = subprocess.run(
        [sys.executable, "-m", "twolink_pin_entry", "simulate", "pd", "--duration", "0.1", "--save", "r.npz"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert ready.read_text().split() == ["started", "parsed", "running", "writing"]


def test_without_the_variable_nothing_is_written(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "twolink_pin_entry", "ik", "5", "5"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert list(tmp_path.iterdir()) == []
