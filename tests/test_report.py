"""``twolink-pin report``: the page a student opens, checked in headless Chromium."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from browser import network_requests, require_chromium, start_chromium

from twolink_pin import OutputError, SimulationConfig
from twolink_pin.controllers import CONTROLLERS
from twolink_pin.report import MARKER, ReportOptions, build_report

SHORT = ReportOptions(config=SimulationConfig(duration=4.0), workers=1)


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rep") / "out"
    build_report(out, SHORT, command_line="pytest")
    return out


def test_results_json_holds_every_controller_and_the_model(report_dir: Path) -> None:
    results = json.loads((report_dir / "results.json").read_text())
    assert list(results["controllers"]) == list(CONTROLLERS)
    assert results["model"]["closed_form_check"]["max_abs_dM"] < 1e-12
    assert results["model"]["p"]["p1"] == pytest.approx(3.4, abs=1e-12)
    csv_rows = (report_dir / "table2.csv").read_text().strip().splitlines()
    assert len(csv_rows) == 1 + 4 * len(CONTROLLERS) + len(CONTROLLERS)  # header, 4 rows each, report rows


@pytest.mark.browser
def test_index_html_images_tables_and_animation_in_chromium(report_dir: Path) -> None:
    """Every image decodes, the tables have their rows, the animation link opens a scene."""
    require_chromium()
    with start_chromium(1280, 900) as driver:
        driver.get((report_dir / "index.html").as_uri())
        images = driver.execute_script(
            "return Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth]);"
        )
        assert len(images) >= 4 + 5 * len(CONTROLLERS)
        broken = [src for src, complete, width in images if not (complete and width > 0)]
        assert broken == []
        rows = driver.execute_script(
            "const n = id => document.querySelectorAll('#' + id + ' tbody tr').length;"
            "return {t1: n('table1'), rms: n('table2-rms'), rep: n('table2-report'), coef: n('coefficients')};"
        )
        assert rows == {"t1": 4, "rms": len(CONTROLLERS), "rep": 5, "coef": 11}
        first_cells = driver.execute_script(
            "return Array.from(document.querySelectorAll('#table2-rms tbody tr td:first-child'))"
            ".map(td => td.textContent);"
        )
        assert first_cells == list(CONTROLLERS)
        external = [u for u in network_requests(driver) if not u.startswith(("file:", "data:"))]
        assert external == []
        href = driver.find_element("id", "animation-link").get_attribute("href")
        driver.get(href)
        driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "const t0 = Date.now(); (function poll() {"
            " if (window.sceneLoaded || Date.now() - t0 > 20000) done(); else setTimeout(poll, 100); })();"
        )
        assert driver.execute_script("return !!window.sceneLoaded && !!window.viewer;")


def test_refuses_a_directory_that_is_not_a_report(tmp_path: Path) -> None:
    target = tmp_path / "mine"
    target.mkdir()
    (target / "thesis.tex").write_text("precious")
    with pytest.raises(OutputError, match="refusing to overwrite"):
        build_report(target, SHORT)
    assert (target / "thesis.tex").read_text() == "precious"


def test_failure_midway_leaves_the_previous_report_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / MARKER).write_text("")
    (out / "index.html").write_text("previous report")

    import twolink_pin.report as report

    def boom(*args: object, **kwargs: object) -> None:
        raise RuntimeError("disk full")

    monkeypatch.setattr(report, "_write_pages", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        build_report(out, ReportOptions(config=SimulationConfig(duration=0.5), workers=1, animation=False))
    assert (out / "index.html").read_text() == "previous report"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging directory left behind
