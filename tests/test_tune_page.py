"""The tuner's page as a person uses it (issues 38, 45, 48), in a real Chromium from the
keyboard: a typed gain runs on Enter only (nothing runs at each keystroke), reads exponent
notation as typed, refuses NaN next to its box and moves a slider's end to reach a typed
value; the box beside a gain's slider and the run's and plant's number boxes take what is
typed the same way, once, and a negative duration is refused where it was typed; the
periods control makes a run of two periods whose "last period" differs from the whole;
"keep this run" names the kept run as ``compare`` names the variant; a full matrix gain
keeps its off-diagonal terms in the page, the runs and the command line."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from browser import require_chromium, start_chromium
from test_tune_browser import WAIT, Tune, page_text, press, ran, slider

pytestmark = [pytest.mark.browser]


def box(driver: Any, label: str) -> Any:
    """The input of the text box labelled ``label`` (a gain's ``NAME =``)."""
    from selenium.webdriver.support.ui import WebDriverWait

    script = """
    var l = Array.from(document.querySelectorAll('label')).find(function (e) { return e.textContent === arguments[0]; });
    var n = l;
    for (var i = 0; n && i < 12; i++) { n = n.parentElement; var input = n && n.querySelector('input'); if (input) return input; }
    return null;
    """.replace("arguments[0]", json.dumps(label))
    return WebDriverWait(driver, WAIT).until(lambda d: d.execute_script(script))


def type_into(element: Any, text: str) -> None:
    """Select what the box holds and type ``text``, key by key (no Enter)."""
    from selenium.webdriver.common.action_chains import ActionChains

    driver = element.parent
    driver.execute_script("arguments[0].focus(); arguments[0].select()", element)
    chain = ActionChains(driver)
    for key in text:
        chain.send_keys(key)
    chain.perform()


@pytest.fixture(scope="module")
def driver() -> Iterator[Any]:
    require_chromium()
    with start_chromium(1400, 1000) as d:
        yield d


@pytest.fixture(scope="module")
def pd() -> Iterator[Tune]:
    tune = Tune("pd", "--duration", "4")
    try:
        yield tune
    finally:
        tune.stop()


def test_a_typed_gain_runs_on_enter_not_at_each_keystroke(pd: Tune, driver: Any) -> None:
    """ "120" typed into ``kd =`` key by key, then Enter: one change reaches the tuner (the
    run's number, which counts every change the tuner was sent, superseded ones included,
    is the previous one + 1) and it runs kd = 120 on both joints; the box then shows the
    value that ran."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    first = pd.next(ran)
    driver.get(pd.url)
    kd = box(driver, "kd =")
    assert kd.get_attribute("value") == "40, 50"
    type_into(kd, "120")
    press(kd, Keys.ENTER)
    typed = pd.next(ran)
    assert typed["gains"]["kd"] == [120.0, 120.0]
    assert typed["run"] == first["run"] + 1
    WebDriverWait(driver, WAIT).until(lambda d: box(d, "kd =").get_attribute("value") == "120, 120")
    press(slider(driver, "kp joint 1 [N·m/rad]"), Keys.ARROW_RIGHT)  # a slider still runs at once
    moved = pd.next(ran)
    assert moved["gains"] == {"kp": [400.0, 300.0], "kd": [120.0, 120.0]} and moved["run"] == typed["run"] + 1


def test_exponent_notation_beyond_the_slider_and_nan_next_to_the_box(pd: Tune, driver: Any) -> None:
    """``1e3`` runs kd = 1000 (not 13) and moves the slider's end from 160 to 1000; ``NaN``
    is refused next to the box, which keeps it, and nothing runs."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    kd = box(driver, "kd =")
    type_into(kd, "1e3, 5e1")
    press(kd, Keys.ENTER)
    line = pd.next(ran)
    assert line["gains"]["kd"] == [1000.0, 50.0]
    thumb = slider(driver, "kd joint 1 [N·m·s/rad]")
    WebDriverWait(driver, WAIT).until(lambda d: float(thumb.get_attribute("aria-valuemax")) >= 1000.0)
    assert float(thumb.get_attribute("aria-valuenow")) == 1000.0
    type_into(kd, "NaN")
    press(kd, Keys.ENTER)
    WebDriverWait(driver, WAIT).until(lambda d: "refused: kd = 'NaN' is invalid" in page_text(d))
    assert box(driver, "kd =").get_attribute("value") == "NaN"


def test_two_periods_make_the_last_period_differ_from_the_whole_run(pd: Tune, driver: Any) -> None:
    from selenium.webdriver.common.keys import Keys

    press(slider(driver, "periods"), Keys.ARROW_RIGHT)
    line = pd.next(ran)
    assert line["spec"]["simulation"]["duration"] == 8.0
    metrics = line["metrics"]
    assert max(metrics["final_period_max_abs_e"]) < 0.5 * max(metrics["max"]["e"])


def test_keep_this_run_names_its_column_as_compare_names_the_variant(pd: Tune, driver: Any) -> None:
    """The kept run's column reads back (``parse_variant``) to the gains it ran with."""
    from selenium.webdriver.support.ui import WebDriverWait

    from twolink_pin.law_variant import parse_variant

    last = [x for x in pd.seen if ran(x)][-1]
    button = WebDriverWait(driver, WAIT).until(
        lambda d: d.execute_script(
            "return Array.from(document.querySelectorAll('button')).find(b => b.textContent === 'keep this run')"
        )
    )
    button.click()
    header = WebDriverWait(driver, WAIT).until(  # the column is headed "kept", its name under the table
        lambda d: d.execute_script(
            "var t = Array.from(document.querySelectorAll('table')).find(e => e.textContent.includes('RMS e [rad]'));"
            "var h = t ? Array.from(t.querySelectorAll('thead th')).map(e => e.textContent) : [];"
            "var c = document.querySelector('code.twolink-kept');"
            "return h.length > 4 && h[h.length - 1] === 'kept' && c ? c.textContent : null"
        )
    )
    variant = parse_variant(header)
    assert variant.law == "pd"
    for name, value in variant.gains:
        np.testing.assert_array_equal(np.ravel(value), np.ravel(last["gains"][name]))
    assert {name for name, _ in variant.gains} == {"kp", "kd"}  # both moved from their defaults


def number_box(driver: Any, label: str, index: int = 0) -> Any:
    """The ``index``-th input of the row labelled ``label`` (a slider's box: its only one)."""
    from selenium.webdriver.support.ui import WebDriverWait

    script = """
    var l = Array.from(document.querySelectorAll('label')).find(function (e) { return e.textContent === arguments[0]; });
    var n = l;
    for (var i = 0; n && i < 12; i++) { n = n.parentElement; var all = n && n.querySelectorAll('input:not([type=hidden])'); if (all && all.length) return all[arguments[1]] || null; }
    return null;
    """.replace("arguments[0]", json.dumps(label)).replace("arguments[1]", str(index))
    return WebDriverWait(driver, WAIT).until(lambda d: d.execute_script(script))


def test_the_box_beside_a_gains_slider_runs_what_is_typed_once(pd: Tune, driver: Any) -> None:
    """Issue 45: "1.2e2" typed key by key into the box beside "kd joint 1", then Enter: one
    run with kd = 120 (exponent notation read as the ``kd =`` box reads it), the box shows
    it; leaving the box afterwards runs nothing more; Enter on a box left as it was runs
    nothing; "abc" is refused next to the gain and nothing runs."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    before = [x for x in pd.seen if ran(x)][-1]
    box = number_box(driver, "kd joint 1 [N·m·s/rad]")
    type_into(box, "1.2e2")
    press(box, Keys.ENTER)
    line = pd.next(ran)
    assert line["gains"]["kd"] == [120.0, before["gains"]["kd"][1]] and line["run"] == before["run"] + 1
    WebDriverWait(driver, WAIT).until(
        lambda d: number_box(d, "kd joint 1 [N·m·s/rad]").get_attribute("value") == "120"
    )
    press(box, Keys.TAB)  # the box loses focus: no second run
    press(box, Keys.ENTER)  # focused again, nothing typed: nothing runs
    type_into(box, "abc")
    press(box, Keys.ENTER)
    WebDriverWait(driver, WAIT).until(lambda d: "refused: kd joint 1 = 'abc' is invalid" in page_text(d))
    type_into(box, "130")
    press(box, Keys.TAB)  # leaving an edited box runs it
    after = pd.next(ran)
    assert after["gains"]["kd"][0] == 130.0 and after["run"] == line["run"] + 1  # nothing ran between


def test_a_number_typed_into_the_plant_or_run_settings_runs_or_is_refused_visibly(
    pd: Tune, driver: Any
) -> None:
    """ "1.5e0" into ``payload [kg]`` runs 1.5 kg (Mantine's box alone read it as 150); a
    negative duration is refused next to it saying what is expected, and nothing runs; a
    good one then runs."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    driver.find_element("xpath", "//*[text()='plant']").click()  # open the plant's folder
    payload = number_box(driver, "payload [kg]")
    type_into(payload, "1.5e0")
    press(payload, Keys.ENTER)
    line = pd.next(ran)
    assert line["payload"] == 1.5
    duration = number_box(driver, "duration [s]")
    type_into(duration, "-3")
    press(duration, Keys.ENTER)
    WebDriverWait(driver, WAIT).until(
        lambda d: "refused: duration [s] = '-3' is invalid: expected a number from 0.001 to" in page_text(d)
    )
    type_into(duration, "6")
    press(duration, Keys.ENTER)
    after = pd.next(ran)
    assert after["spec"]["simulation"]["duration"] == 6.0 and after["run"] == line["run"] + 1  # -3 never ran
    WebDriverWait(driver, WAIT).until(lambda d: "refused: duration" not in page_text(d))


FULL = [[150.0, 20.0, 0.0], [20.0, 150.0, 0.0], [0.0, 0.0, 80.0]]


@pytest.fixture(scope="module")
def panda() -> Iterator[Tune]:
    tune = Tune("osc", "--robot", "panda", "--gain", "kp=150,20,0,20,150,0,0,0,80", "--duration", "0.5")
    try:
        yield tune
    finally:
        tune.stop()


def test_a_full_matrix_gain_keeps_its_off_diagonals_in_the_page_the_runs_and_the_command(
    panda: Tune, driver: Any
) -> None:
    """The first run and its command carry the whole matrix; the page shows it row by row;
    moving the x diagonal slider changes that entry only; ``simulate`` with the command runs
    the same gains."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait
    from test_tune_browser import simulate_json

    first = panda.next(ran)
    assert first["gains"]["kp"] == FULL
    assert "--gain=kp=150.0,20.0,0.0,20.0,150.0,0.0,0.0,0.0,80.0" in first["command"]
    driver.get(panda.url)
    assert box(driver, "kp =").get_attribute("value") == "150, 20, 0; 20, 150, 0; 0, 0, 80"
    press(slider(driver, "kp axis x [1/s²]"), Keys.ARROW_RIGHT)  # 150 · 10^(1/20) = 168 → 170
    moved = panda.next(ran)
    assert moved["gains"]["kp"] == [[170.0, 20.0, 0.0], [20.0, 150.0, 0.0], [0.0, 0.0, 80.0]]
    WebDriverWait(driver, WAIT).until(
        lambda d: box(d, "kp =").get_attribute("value") == "170, 20, 0; 20, 150, 0; 0, 0, 80"
    )
    assert simulate_json(moved["command"])["gains"] == moved["gains"]
