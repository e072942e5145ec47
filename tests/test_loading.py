"""Finding a law from what a user typed: a name, file.py:Class, module:Class, an entry point;
and every way a reference can be wrong, with its one-line message."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from twolink_pin.controllers import (
    CONTROLLERS,
    PDFeedforward,
    available_controllers,
    load_controller,
    loading,
)
from twolink_pin.errors import ControllerSpecError

LAW = '''
from dataclasses import dataclass
from typing import Any
from twolink_pin import Controller, Gains, LawOutput, gain

@dataclass(frozen=True, eq=False)
class NullGains(Gains):
    scale: Any = gain(1.0, bound="nonnegative")

class Null(Controller):
    """τ = 0."""
    name = "{name}"
    title = "zero torque"
    Gains = NullGains

    def compute(self, x, terms):
        return LawOutput(0.0 * x.q)
'''


@pytest.fixture()
def law_file(tmp_path: Path) -> Path:
    path = tmp_path / "null_law.py"
    path.write_text(LAW.replace("{name}", "test-null-from-file"))
    yield path
    CONTROLLERS.pop("test-null-from-file", None)


def test_a_registered_name_gives_its_class() -> None:
    assert load_controller("pd") is PDFeedforward


def test_a_file_reference_imports_the_file_and_registers_the_law(law_file: Path) -> None:
    """path/to/file.py:Class loads the class (its directory is not put on sys.path) and
    the class registers under its name; loading it twice gives the same class."""
    cls = load_controller(f"{law_file}:Null")
    assert cls.name == "test-null-from-file" and CONTROLLERS["test-null-from-file"] is cls
    assert str(law_file.parent) not in sys.path
    assert load_controller(f"{law_file}:Null") is cls


def test_a_module_reference_imports_the_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "my_laws.py").write_text(LAW.replace("{name}", "test-null-from-module"))
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        cls = load_controller("my_laws:Null")
        assert cls.name == "test-null-from-module"
    finally:
        CONTROLLERS.pop("test-null-from-module", None)
        sys.modules.pop("my_laws", None)


def test_an_installed_entry_point_adds_a_law(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A distribution declaring [twolink_pin.controllers] null = plugin_laws:Null makes the law
    available by name (importlib.metadata finds the dist-info on sys.path)."""
    (tmp_path / "plugin_laws.py").write_text(LAW.replace("{name}", "test-null-plugin"))
    info = tmp_path / "twolink_pin_test_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: twolink-pin-test-plugin\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[twolink_pin.controllers]\nnull = plugin_laws:Null\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(loading, "_entry_points_loaded", False)
    try:
        assert "test-null-plugin" in available_controllers()
        assert load_controller("test-null-plugin").title == "zero torque"
    finally:
        CONTROLLERS.pop("test-null-plugin", None)
        sys.modules.pop("plugin_laws", None)


@pytest.mark.parametrize(
    ("make", "text"),
    [
        (lambda d: "lqr", "no law of that name; registered laws are pd, computed-torque, robust, adaptive"),
        (lambda d: f"{d}/absent.py:Law", "no such file"),
        (lambda d: f"{d}:Law", "not a regular file"),
        (lambda d: f"{d / 'law.txt'}:Law", "expected a Python file ending in .py"),
        (lambda d: f"{d / 'broken.py'}:Law", "importing .*broken.py raised SyntaxError"),
        (lambda d: f"{d / 'raises.py'}:Law", "importing .*raises.py raised RuntimeError: no robot here"),
        (lambda d: f"{d / 'plain.py'}:Missing", "has no class 'Missing'"),
        (lambda d: f"{d / 'plain.py'}:NotALaw", "NotALaw is not a twolink_pin Controller subclass"),
        (lambda d: "no_such_module_xyz:Law", "cannot import module 'no_such_module_xyz'"),
        (lambda d: "twolink_pin.controllers.base:Controller", "Controller is abstract"),
        (lambda d: "", "expected a law name"),
    ],
)
def test_bad_references_say_what_is_wrong(tmp_path: Path, make, text: str) -> None:  # type: ignore[no-untyped-def]
    (tmp_path / "law.txt").write_text("")
    (tmp_path / "broken.py").write_text("def (:\n")
    (tmp_path / "raises.py").write_text("raise RuntimeError('no robot here')\n")
    (tmp_path / "plain.py").write_text("class NotALaw:\n    pass\n")
    with pytest.raises(ControllerSpecError, match=text) as info:
        load_controller(make(tmp_path))
    assert "\n" not in str(info.value)


def test_the_cli_reports_a_bad_reference_in_one_line_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from twolink_pin.cli import main

    (tmp_path / "plain.py").write_text("class NotALaw:\n    pass\n")
    for argv in (
        ["simulate", f"{tmp_path / 'plain.py'}:NotALaw"],
        ["sweep", "nope", "--samples", "2"],
        ["compare", "nope"],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert re.match(r"twolink-pin: error: controller '.*'", err) and err.count("\n") == 1
