"""The tuning page as a person meets it on a laptop's and a desktop's screen (issue 48), in a
real Chromium at 1366×768 and 1920×1080, on ``tune mpc`` (about twenty gain rows): with a
slider far down the controls focused and moved from the keyboard, the metrics table, the
first plot and that slider are all in view and uncovered, and the table shows the new run;
mpc's horizon moves by one knot a key press and follows its knot interval in whole knots."""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from browser import require_chromium, start_chromium
from test_tune_browser import WAIT, Tune, page_text, press, ran, slider
from test_tune_page import number_box, type_into

pytestmark = [pytest.mark.browser]

SIZES = ((1366, 768), (1920, 1080))

GEOMETRY = """
var inView = function (r) { return r.width > 0 && r.left >= 0 && r.top >= 0 && r.right <= innerWidth && r.bottom <= innerHeight; };
var uncovered = function (el) {
  var r = el.getBoundingClientRect();
  var hit = document.elementFromPoint(r.left + r.width / 2, r.top + Math.min(r.height / 2, 10));
  return hit !== null && (el.contains(hit) || hit.contains(el));
};
var table = Array.from(document.querySelectorAll('table')).find(e => e.textContent.includes('RMS e [rad]'));
var plot = document.querySelector('.uplot');
var thumb = document.activeElement;
return {
  table: !!table && inView(table.getBoundingClientRect()) && uncovered(table),
  plot: !!plot && inView(plot.getBoundingClientRect()) && uncovered(plot),
  thumb: !!thumb && thumb.getAttribute('role') === 'slider' && inView(thumb.getBoundingClientRect()) && uncovered(thumb),
  apart: !!table && !!thumb && (table.getBoundingClientRect().left >= thumb.getBoundingClientRect().right)
};
"""
"""Whether the table, the first plot and the focused slider are inside the window and the
topmost element at their place (nothing floats over them), and the results right of it."""


@pytest.fixture(scope="module")
def mpc() -> Iterator[Tune]:
    tune = Tune("mpc", "--duration", "0.5")
    try:
        tune.next(ran)  # the defaults' run
        yield tune
    finally:
        tune.stop()


@contextmanager
def sized(width: int, height: int) -> Iterator[Any]:
    """A Chromium whose page is exactly ``width`` × ``height`` CSS pixels."""
    require_chromium()
    with start_chromium(width, height) as driver:
        driver.execute_cdp_cmd(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        )
        yield driver


@pytest.fixture(scope="module")
def laptop() -> Iterator[Any]:
    with sized(*SIZES[0]) as driver:
        yield driver


def check_in_view(mpc: Tune, driver: Any) -> None:
    """Focus mpc's last gain's slider, press ←, wait for the run on the page: the table, the
    first plot and the slider are in view and uncovered, the results right of the slider."""
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    driver.get(mpc.url)
    thumb = slider(driver, "limit_scale")  # far down, below twenty rows of controls
    before = float(thumb.get_attribute("aria-valuenow"))
    press(thumb, Keys.ARROW_LEFT)  # the controls' column scrolls it into view; 0.05 down
    line = mpc.next(lambda x: ran(x) and abs(x["gains"]["limit_scale"] - (before - 0.05)) < 1e-9)
    WebDriverWait(driver, WAIT).until(lambda d: f"run {line['run']}: " in page_text(d))
    where = driver.execute_script(GEOMETRY)
    assert where == {"table": True, "plot": True, "thumb": True, "apart": True}, where


def test_at_1366_by_768_the_table_and_a_plot_stay_in_view_while_a_slider_far_down_moves(
    mpc: Tune, laptop: Any
) -> None:
    check_in_view(mpc, laptop)


def test_at_1920_by_1080_the_table_and_a_plot_stay_in_view_while_a_slider_far_down_moves(mpc: Tune) -> None:
    with sized(*SIZES[1]) as driver:
        check_in_view(mpc, driver)


def test_the_horizon_moves_one_knot_a_press_and_follows_its_knot_interval(mpc: Tune, laptop: Any) -> None:
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    driver = laptop
    press(slider(driver, "horizon [s]"), Keys.ARROW_RIGHT)
    line = mpc.next(lambda x: ran(x) and x["gains"]["horizon"] != 0.2)
    assert line["gains"]["horizon"] == 9 * 0.025 and line["gains"]["knot_interval"] == 0.025
    box = number_box(driver, "knot_interval [s]")
    type_into(box, "0.03")
    press(box, Keys.ENTER)
    moved = mpc.next(lambda x: ran(x) and x["gains"]["knot_interval"] == 0.03)
    assert moved["gains"]["horizon"] == 8 * 0.03  # 0.225 s is 7.5 knots of 0.03 s: 8 (half to even)
    assert f"--gain=horizon={json.dumps(8 * 0.03)}" in moved["command"]
    WebDriverWait(driver, WAIT).until(lambda d: "horizon rounded to 8 × knot_interval" in page_text(d))
