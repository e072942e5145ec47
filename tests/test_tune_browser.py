"""``tune`` in a real Chromium, driven by the keyboard: the page draws the arm, a gain's
slider re-runs the law, the latest setting wins, the reproducing ``simulate`` line gives the
same metrics, a user's law gets its own controls, ``--watch`` reloads it, refused values,
a law that raises and a diverging run leave the server up, Ctrl-C ends it cleanly, and two
tabs (one closed and reopened) show the same latest run.

The runs are observed through ``tune --json``'s lines on stdout (one per finished run);
every wait is on a condition, bounded by :data:`WAIT` (a failure when it runs out)."""

from __future__ import annotations

import json
import os
import queue
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import require_chromium, screenshot, start_chromium

pytestmark = [pytest.mark.browser]

ROOT = Path(__file__).resolve().parents[1]
WAIT = 600.0
"""Bound on every wait [s] (a busy machine): a failure, never a pass, when it runs out."""
CLI = [sys.executable, "-m", "twolink_pin_entry"]
VIEW = slice(40, 480)
"""The columns [px] of a 1400-px window where the arm is drawn: left of the controls, which
float over the 3-D view's right part (the results are docked at the window's right edge)."""
SHORT = ("--duration", "4")
"""The tuner's runs here: 4 s simulated (its default, 30 s, made every run and every redraw
of the page 7.5 times longer; nothing checked here depends on the length)."""


class Tune:
    """A ``twolink-pin tune … --json --no-browser`` process and its stdout lines."""

    def __init__(self, *args: str, cwd: Path = ROOT) -> None:
        self.proc = subprocess.Popen(
            [*CLI, "tune", *args, "--json", "--no-browser"],
            cwd=cwd,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.lines: queue.Queue[dict[str, Any]] = queue.Queue()
        self.seen: list[dict[str, Any]] = []
        self.stderr: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        self.stderr_reader = threading.Thread(
            target=lambda: self.stderr.extend(self.proc.stderr), daemon=True
        )  # type: ignore[arg-type]
        self.stderr_reader.start()
        self.url = self.next(lambda line: "url" in line)["url"]

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for text in self.proc.stdout:
            self.lines.put(json.loads(text))

    def next(self, wanted: Callable[[dict[str, Any]], bool]) -> dict[str, Any]:
        """The next line (after those already read) that ``wanted`` accepts."""
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=1.0)
            except queue.Empty:
                assert self.proc.poll() is None, f"tune exited: {''.join(self.stderr)}"
                continue
            self.seen.append(line)
            if wanted(line):
                return line
        raise AssertionError(f"no such line within {WAIT} s; seen {self.seen[-3:]}")

    def interrupt(self) -> tuple[int, str]:
        """Ctrl-C: the exit status and stderr."""
        self.proc.send_signal(signal.SIGINT)
        code = self.proc.wait(timeout=WAIT)
        self.stderr_reader.join(WAIT)  # it ends with the pipe: all of stderr is read
        return code, "".join(self.stderr)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def ran(line: dict[str, Any]) -> bool:
    return "metrics" in line


@pytest.fixture(scope="module")
def driver() -> Iterator[Any]:
    require_chromium()
    with start_chromium(1400, 1000) as d:
        yield d


def slider(driver: Any, label: str) -> Any:
    """The thumb of the slider labelled ``label`` (it takes the arrow keys)."""
    from selenium.webdriver.support.ui import WebDriverWait

    script = """
    var labels = Array.from(document.querySelectorAll('label'));
    var l = labels.find(function (e) { return e.textContent === arguments[0]; });
    return l ? document.getElementById(l.htmlFor).querySelector('[role=slider]') : null;
    """.replace("arguments[0]", json.dumps(label))
    return WebDriverWait(driver, WAIT).until(lambda d: d.execute_script(script))


def labels(driver: Any) -> list[str]:
    return driver.execute_script(
        "return Array.from(document.querySelectorAll('label')).map(e => e.textContent)"
    )


def page_text(driver: Any) -> str:
    return driver.execute_script("return document.body.innerText")


def press(element: Any, *keys: str) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    driver = element.parent
    driver.execute_script("arguments[0].focus()", element)
    ActionChains(driver).send_keys(*keys).perform()


def simulate_json(command: str) -> dict[str, Any]:
    argv = shlex.split(command)
    assert argv[:2] == ["twolink-pin", "simulate"]
    out = subprocess.run([*CLI, *argv[1:], "--json"], cwd=ROOT, capture_output=True, text=True, timeout=WAIT)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.fixture(scope="module")
def pd() -> Iterator[Tune]:
    tune = Tune("pd", *SHORT)
    try:
        yield tune
    finally:
        tune.stop()


def test_the_page_draws_the_arm_and_a_gain_moved_by_keyboard_runs_again(pd: Tune, driver: Any) -> None:
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    first = pd.next(ran)
    assert first["gains"] == {"kp": [350.0, 300.0], "kd": [40.0, 50.0]}  # the report's gains
    driver.get(pd.url)
    thumb = slider(driver, "kp joint 1 [N·m/rad]")

    def drawn(d: Any) -> bool:  # the arm (and its trail) in the 3-D view left of the floating controls
        view = screenshot(d)[150:850, VIEW, :3]
        return bool((view.min(axis=2) < 0.8).mean() > 0.01)

    WebDriverWait(driver, WAIT).until(drawn)
    press(thumb, Keys.ARROW_RIGHT)  # one step of the log grid: 350 → 400
    line = pd.next(ran)
    assert line["gains"]["kp"] == [400.0, 300.0]
    assert "--gain=kp=400.0,300.0" in line["command"]
    assert line["metrics"] != first["metrics"]


def test_after_a_burst_the_last_line_carries_the_final_value(pd: Tune, driver: Any) -> None:
    """Five presses, five grid steps (400 → 450 → 500 → 550 → 600 → 700): the values
    reported never go back (a stale run never follows a newer one) and the last is the
    control's final value; a later change of another gain runs with it."""
    from selenium.webdriver.common.keys import Keys

    thumb = slider(driver, "kp joint 1 [N·m/rad]")
    start = float(thumb.get_attribute("aria-valuenow"))
    assert start == 400.0
    press(thumb, *[Keys.ARROW_RIGHT] * 5)
    final = 700.0
    pd.next(lambda line: ran(line) and line["gains"]["kp"][0] == final)
    press(slider(driver, "kd joint 2 [N·m·s/rad]"), Keys.ARROW_LEFT)  # 50 → 45: one step down
    last = pd.next(lambda line: ran(line) and line["gains"]["kd"][1] == 45.0)
    assert last["gains"]["kp"][0] == final
    burst = [line["gains"]["kp"][0] for line in pd.seen if ran(line) and line["gains"]["kp"][0] > start]
    assert burst == sorted(burst) and burst[-1] == final


def test_the_reported_command_gives_the_same_metrics_as_simulate(pd: Tune) -> None:
    """The last run's ``simulate`` line, run on its own: the same gains and the same
    metrics, number for number."""
    line = [x for x in pd.seen if ran(x)][-1]
    alone = simulate_json(line["command"])
    assert alone["gains"] == line["gains"]
    assert alone["metrics"] == line["metrics"]
    assert alone["plant"] == line["plant"]


def test_a_refused_value_shows_the_laws_message_and_the_server_stays_up(pd: Tune, driver: Any) -> None:
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    thumb = slider(driver, "kp joint 1 [N·m/rad]")
    press(thumb, Keys.HOME)  # kp = 0: pd's gains are > 0
    refused = pd.next(lambda line: "error" in line)
    said = "kp = [0.0, 300.0] is invalid: expected a symmetric positive-definite matrix gain"
    assert refused["error"].startswith(said)  # pd's kp is a matrix gain: its message names the check
    assert "a diagonal entry is not > 0 (smallest 0)" in refused["error"]
    WebDriverWait(driver, WAIT).until(lambda d: f"refused: {said}" in page_text(d))
    press(thumb, Keys.ARROW_RIGHT)  # up from 0: a hundredth of the slider's range, 14
    assert pd.next(ran)["gains"]["kp"][0] == 14.0


def test_two_tabs_show_the_same_latest_run_and_a_reopened_tab_draws_with_its_controls(
    pd: Tune, driver: Any
) -> None:
    """Two tabs on one tuner (the first is the page the tests above drove): a gain moved in
    the first is the second's control value and both show that run; the second closed and
    opened again draws the arm and has the controls and the latest run."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    first_tab = driver.current_window_handle
    assert driver.current_url == pd.url
    try:
        thumb = slider(driver, "kp joint 1 [N·m/rad]")
        before = [x for x in pd.seen if ran(x)][-1]["gains"]["kp"]
        driver.switch_to.new_window("tab")
        second_tab = driver.current_window_handle
        driver.get(pd.url)
        slider(driver, "kp joint 1 [N·m/rad]")
        driver.switch_to.window(first_tab)
        press(thumb, Keys.ARROW_RIGHT)
        line = pd.next(ran)
        moved = 16.0  # from 14, one step of the preferred grid (350 is a preferred value)
        assert before[0] == 14.0 and line["gains"]["kp"] == [moved, before[1]]
        shown = f"run {line['run']}: "

        def latest(d: Any) -> bool:
            value = slider(d, "kp joint 1 [N·m/rad]").get_attribute("aria-valuenow")
            return float(value) == moved and shown in page_text(d)

        WebDriverWait(driver, WAIT).until(latest)
        driver.switch_to.window(second_tab)
        WebDriverWait(driver, WAIT).until(latest)
        driver.close()
        driver.switch_to.window(first_tab)
        driver.switch_to.new_window("tab")
        driver.get(pd.url)
        WebDriverWait(driver, WAIT).until(latest)
        assert {"kp joint 1 [N·m/rad]", "kd joint 2 [N·m·s/rad]"} <= set(labels(driver))
        WebDriverWait(driver, WAIT).until(
            lambda d: bool((screenshot(d)[150:850, VIEW, :3].min(axis=2) < 0.8).mean() > 0.01)
        )
    finally:
        for handle in driver.window_handles:
            if handle != first_tab:
                driver.switch_to.window(handle)
                driver.close()
        driver.switch_to.window(first_tab)


def test_ctrl_c_ends_the_server_cleanly(pd: Tune) -> None:
    code, err = pd.interrupt()
    assert code == 0, err
    assert "Traceback" not in err
    assert "(viser)" not in err  # Viser's "Server stopped" line is not ours to print


@pytest.fixture(scope="module")
def own_law(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Tune, Path]]:
    folder = tmp_path_factory.mktemp("law")
    law = folder / "sliding_mode.py"
    shutil.copy(ROOT / "examples" / "sliding_mode.py", law)
    tune = Tune(f"{law}:SlidingMode", "--watch", *SHORT, cwd=folder)
    try:
        yield tune, law
    finally:
        tune.stop()


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    stat = path.stat()
    path.write_text(text.replace(old, new))
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))  # a new time even on a coarse clock


def test_a_users_law_gets_controls_for_its_own_gains(own_law: tuple[Tune, Path], driver: Any) -> None:
    tune, _ = own_law
    first = tune.next(ran)
    assert set(first["gains"]) == {"k", "ks", "phi", "lam"}
    driver.get(tune.url)
    slider(driver, "phi [rad/s]")
    shown = labels(driver)
    for label in ("k joint 1 [N·m·s/rad]", "ks joint 2 [N·m]", "k × (all)", "phi [rad/s]", "lam [1/s]"):
        assert label in shown


def test_watch_reloads_an_edited_law_and_survives_one_that_raises_or_diverges(
    own_law: tuple[Tune, Path], driver: Any
) -> None:
    from selenium.webdriver.support.ui import WebDriverWait

    tune, law = own_law
    before = [x for x in tune.seen if ran(x)][-1]
    _edit(law, "return LawOutput(tau - g.k * s", "return LawOutput(tau - 2.0 * g.k * s")
    edited = tune.next(ran)
    assert edited["metrics"] != before["metrics"]
    _edit(
        law,
        "return LawOutput(tau - 2.0 * g.k * s",
        "raise RuntimeError('bad law')\n        return LawOutput(tau - g.k * s",
    )
    raised = tune.next(lambda line: "error" in line)
    assert "RuntimeError: bad law" in raised["error"] and f"{law}:" in raised["error"]
    WebDriverWait(driver, WAIT).until(lambda d: "RuntimeError: bad law" in page_text(d))
    wild = "return LawOutput((1e9 if float(np.max(x.t)) > 1.0 else 1.0) * tau - g.k * s"
    _edit(  # sane at the start (a law wild from t = 0 is refused before it runs: the step check)
        law, "raise RuntimeError('bad law')\n        return LawOutput(tau - g.k * s", wild
    )
    diverged = tune.next(lambda line: "error" in line)
    assert "diverged at t = " in diverged["error"]
    _edit(law, wild, "return LawOutput(tau - g.k * s")
    again = tune.next(ran)
    np.testing.assert_array_equal(again["metrics"]["rms"]["e"], before["metrics"]["rms"]["e"])
    code, err = tune.interrupt()
    assert code == 0 and "Traceback" not in err
