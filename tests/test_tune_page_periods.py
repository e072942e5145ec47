"""tune's page shows each finished period of a run in flight (issue 38, items 1 and 5), in a
real Chromium from the keyboard, deterministically (no timing): a user's PD whose ``compute``
waits for a file once ``t > 1.5`` periods in any run but the defaults' makes the run after a
key press stop in its second period; the page then shows "period 1 of 3" and the metrics of
the first period — this run's and the previous (defaults) run's, cut to it — which equal
``simulate`` of ONE period of the same law and gains (a second run, printed to the table's
digits); once the file exists, the complete run's table and status replace them."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import require_chromium, start_chromium
from test_tune_browser import CLI, WAIT, Tune, press, ran, slider

pytestmark = [pytest.mark.browser]

LAW = '''
import time
from pathlib import Path

import numpy as np

from twolink_pin.controllers.pd import PDFeedforward

GATE = Path(__file__).with_name("gate")
FIRST = []


class WaitingPD(PDFeedforward):
    """PD + feedforward that, in a run whose kp differs from the first run's, waits for the
    file ``gate`` beside it once t > 6 s (1.5 periods of the twolink's 4-s reference)."""

    name = "waiting-pd"

    def compute(self, x, terms):
        kp = float(np.ravel(self.gains.kp)[0])
        FIRST[:] = FIRST or [kp]
        if float(np.max(x.t)) > 6.0 and kp != FIRST[0]:
            deadline = time.monotonic() + 600.0
            while not GATE.exists() and time.monotonic() < deadline:
                time.sleep(0.02)
        return super().compute(x, terms)
'''

TABLE_JS = """
var t = Array.from(document.querySelectorAll('table')).find(e => e.textContent.includes('RMS e [rad]'));
if (!t) return null;
var rows = {};
Array.from(t.querySelectorAll('tr')).forEach(function (r) {
  var c = Array.from(r.querySelectorAll('th, td')).map(e => e.textContent.trim());
  rows[c[0]] = c.slice(1);
});
return rows;
"""
"""The metrics table as ``{row name: [cells]}`` (the header row under ``""``)."""


def cells(values: list[float]) -> str:
    """A cell as the page prints it (:func:`~twolink_pin.tuning.app.metrics_table`)."""
    return ", ".join(f"{x:.3g}" for x in values)


def one_period(law: str, folder: Path, gains: dict[str, Any]) -> dict[str, Any]:
    """``simulate --json`` of one period (4 s) of ``law`` with ``gains`` (a matrix row by row):
    the second method."""
    options = [
        f"--gain={name}={','.join(repr(float(x)) for x in np.ravel(value))}" for name, value in gains.items()
    ]
    argv = [*CLI, "simulate", law, *options, "--duration=4", "--json"]
    out = subprocess.run(argv, cwd=folder, capture_output=True, text=True, timeout=WAIT)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)["metrics"]


def column(metrics: dict[str, Any]) -> dict[str, str]:
    """The rows of a column of the table as the page prints them for ``metrics``."""
    return {
        "RMS e [rad]": cells(metrics["rms"]["e"]),
        "max |e| [rad]": cells(metrics["max"]["e"]),
        "last period max |e| [rad]": cells(metrics["final_period_max_abs_e"]),
        "RMS τ [N·m]": cells(metrics["rms"]["tau"]),
        "max |τ| [N·m]": cells(metrics["max"]["tau"]),
    }


@pytest.fixture(scope="module")
def driver() -> Iterator[Any]:
    require_chromium()
    with start_chromium(1400, 1000) as d:
        yield d


@pytest.fixture()
def waiting(tmp_path: Path) -> Iterator[tuple[Tune, Path]]:
    (tmp_path / "waiting_pd.py").write_text(LAW)
    tune = Tune(f"{tmp_path / 'waiting_pd.py'}:WaitingPD", "--timeout=600", cwd=tmp_path)
    try:
        yield tune, tmp_path
    finally:
        (tmp_path / "gate").touch()  # a run still waiting ends
        tune.stop()


def test_a_run_in_flight_shows_its_first_period_with_every_column_cut_to_it(
    waiting: tuple[Tune, Path], driver: Any
) -> None:
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    tune, folder = waiting
    law = f"{folder / 'waiting_pd.py'}:WaitingPD"
    first = tune.next(ran)  # the defaults' run: three periods, never waits
    assert first["spec"]["simulation"]["duration"] == 12.0
    driver.get(tune.url)
    WebDriverWait(driver, WAIT).until(lambda d: f"run {first['run']}: 12 s simulated" in d.page_source)
    thumb = slider(driver, "kp joint 1 [N·m/rad]")
    press(thumb, Keys.ARROW_RIGHT)  # kp moves one step: this run waits at t > 6 s
    kp = [list(row) for row in first["gains"]["kp"]]  # a user's PD: Kp = ω² M(q₀), a full (2, 2) matrix
    kp[0][0] = float(thumb.get_attribute("aria-valuenow"))  # the slider sets its diagonal, the rest kept
    moved = {**first["gains"], "kp": kp}
    assert kp[0][0] > first["gains"]["kp"][0][0]
    status = f"run {first['run'] + 1}: period 1 of 3 shown"
    WebDriverWait(driver, WAIT).until(lambda d: status in d.execute_script("return document.body.innerText"))
    text = driver.execute_script("return document.body.innerText")
    assert "over period 1 of 3" in text and "running…" in text
    table = driver.execute_script(TABLE_JS)
    assert table[""] == ["this run", "previous", "defaults"]
    this, defaults = one_period(law, folder, moved), one_period(law, folder, first["gains"])
    for row, want in column(this).items():
        assert table[row][0] == want, row
    for row, want in column(defaults).items():  # the previous run (the defaults') cut to period 1
        assert table[row][1] == want == table[row][2], row
    assert table["last period max |e| [rad]"] == table["max |e| [rad]"]  # one period: the whole
    (folder / "gate").touch()
    done = tune.next(ran)
    assert done["run"] == first["run"] + 1 and done["gains"] == moved
    final = f"run {done['run']}: 12 s simulated"
    WebDriverWait(driver, WAIT).until(lambda d: final in d.execute_script("return document.body.innerText"))
    table = driver.execute_script(TABLE_JS)
    for row, want in column(done["metrics"]).items():
        assert table[row][0] == want, row
    assert "over period" not in driver.execute_script("return document.body.innerText")
