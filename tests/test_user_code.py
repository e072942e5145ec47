"""User code outside ``compute`` (``twolink_pin.user_code``): a law's changes to the working
directory and NumPy's global state do not outlive its run, and an error in its file names the
file and the line."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.errors import ControllerSpecError
from twolink_pin.user_code import guarded, process_state

LAWS = Path(__file__).parent / "corpus" / "laws"


def test_a_law_that_changes_numpy_state_does_not_change_the_next_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """compare with a law that sets np.seterr(all='raise'), one-digit printing and a seed:
    afterwards NumPy's state is what it was, and pd's next run equals its run before (to the bit)."""
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "pd", "--duration", "0.3", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    before = np.geterr(), np.get_printoptions()["precision"], np.random.get_state()[1][:4].tolist()  # noqa: NPY002
    law = f"{LAWS}/hostile.py:NumpyState"
    assert main(["compare", law, "pd", "--duration", "0.3", "--no-plot", "--out", "c", "--json"]) == 0
    capsys.readouterr()
    after = np.geterr(), np.get_printoptions()["precision"], np.random.get_state()[1][:4].tolist()  # noqa: NPY002
    assert after == before
    assert main(["simulate", "pd", "--duration", "0.3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["metrics"] == first["metrics"]


def test_guarded_names_the_users_file_and_line_and_restores_the_folder(tmp_path: Path) -> None:
    """An exception raised in a file outside the package is reported at that file's line; a
    chdir inside the block is undone."""
    user = tmp_path / "mylaw.py"
    user.write_text("def build():\n    import os\n    os.chdir('/')\n    raise ValueError('bad gain')\n")
    namespace: dict[str, object] = {}
    exec(compile(user.read_text(), str(user), "exec"), namespace)
    here = os.getcwd()
    with pytest.raises(ControllerSpecError, match=rf"building it raised ValueError: bad gain at {user}:4$"):
        with guarded("mylaw", "building it"):
            namespace["build"]()  # type: ignore[operator]
    assert os.getcwd() == here
    with process_state():
        np.seterr(all="raise")
    assert np.geterr()["divide"] == "warn"
