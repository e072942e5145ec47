"""``twolink-pin report``: the page a student opens, checked in headless Chromium; its numbers
against the library; a sixth law, a non-twolink robot, and failures that leave nothing behind."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from browser import network_requests, require_chromium, start_chromium

from twolink_pin import OutputError, SimulationConfig
from twolink_pin.report import MARKER, ReportOptions, build_report
from twolink_pin.run_spec import RunSpec
from twolink_pin.twolink.reference import REPORT_CONTROLLERS

SHORT = ReportOptions(
    run=RunSpec(simulation=SimulationConfig(duration=4.0)), workers=1, limits_section=False, sim_to_sim=False
)


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rep") / "out"
    build_report(out, SHORT, command_line="pytest")
    return out


def test_results_json_holds_every_controller_and_the_model(report_dir: Path) -> None:
    results = json.loads((report_dir / "results.json").read_text())
    assert list(results["controllers"]) == list(REPORT_CONTROLLERS)
    assert results["twolink"]["closed_form_check"]["max_abs_dM"] < 1e-12
    assert results["robot"]["parameters"]["p1"] == pytest.approx(3.4, abs=1e-12)
    assert results["simulation"]["lambda"] == {
        "computed-torque": 5.0,
        "robust": 5.0,
        "adaptive": 5.0,
        "adaptive-friction": 5.0,
    }
    csv_rows = (report_dir / "comparison.csv").read_text().strip().splitlines()
    # header, 3 norms + last-period row each; then the gains block: its header and a row per law;
    # then the end effector's errors (every law moves it, issue 38): its header and a row per law
    n = len(REPORT_CONTROLLERS)
    assert len(csv_rows) == 1 + 4 * n + 2 * (1 + n)
    assert csv_rows[1 + 4 * n] == "controller,gains"
    assert [r.split(",", 1)[0] for r in csv_rows[2 + 4 * n : 2 + 5 * n]] == list(REPORT_CONTROLLERS)
    assert csv_rows[2 + 5 * n].startswith("controller,task_metric,position_rms_mm")
    assert [r.split(",", 2)[:2] for r in csv_rows[-n:]] == [[law, "task"] for law in REPORT_CONTROLLERS]
    errata = [e["topic"] for e in results["errata"]]
    assert len(errata) == 6 and "Unstated λ, initial state and norm" in errata
    # which plant each law ran on, as compare says it: the report's plant has friction only
    # under the laws that estimate it (the default --plant-friction law)
    plants = results["comparison"]["plants"]
    assert plants == {
        n: "friction" if n == "adaptive-friction" else "no friction" for n in REPORT_CONTROLLERS
    }
    # ... and the gains it ran with (the report's λ = 5 1/s among them), as comparison.md lists them
    row = re.search(
        r"^\| adaptive-friction \| (?P<gains>[^|]+) \| friction \| finished \|$",
        (report_dir / "report.md").read_text(),
        re.MULTILINE,
    )
    assert row is not None and "lam = 5," in row["gains"] and "k = (90, 90)" in row["gains"]


def test_the_derived_equations_beside_the_courses(report_dir: Path) -> None:
    """Issue 47: the model section shows M, C, g derived from the URDF (as MathML) and, for the
    twolink, the derived M and C written in the p they find beside the report's, all equal."""
    results = json.loads((report_dir / "results.json").read_text())
    equations = results["robot"]["equations"]
    assert equations["shown"] and equations["skew_symmetric"] and len(equations["M"]) == 3
    course = results["twolink"]["course_equations"]
    assert course["found"] == {"p1": "beta1 + beta4", "p2": "beta4", "p3": "beta2*l2x"}
    assert course["M"] and course["C"] and course["Y"] and course["p_expressions"]
    html = (report_dir / "index.html").read_text()
    for section in ("equations-beta", "equations-M", "equations-C", "equations-g", "equations-course"):
        assert f'id="{section}"' in html
    table = html[
        html.index('id="equations-course"') : html.index("</table>", html.index('id="equations-course"'))
    ]
    assert table.count("<tr>") == 7 and table.count("<math") == 14
    assert "$$" in (report_dir / "report.md").read_text()


def test_numbers_on_the_page_have_a_stated_precision(report_dir: Path) -> None:
    """No float printed with 15+ digits (e.g. "Peaks [4.093301855416829, ...]")."""
    text = (report_dir / "index.html").read_text()
    body = text[text.index("<body>") :]
    assert not re.findall(r"\d\.\d{9,}", body)


def test_laws_read_as_on_the_site_math_as_mathml(report_dir: Path) -> None:
    """Each law's docstring is rendered (Markdown, its formulas as MathML), not shown as source:
    no ``$$``, no double backticks, no Sphinx role; the adaptive law's update law is a <math>
    whose TeX annotation holds Γ Yᵀ s. The errata's evidence has no numpy array print-out."""
    text = (report_dir / "index.html").read_text()
    laws = re.findall(r'<div class="law">(.*?)</div>', text, re.DOTALL)
    assert len(laws) == len(REPORT_CONTROLLERS)
    for law in laws:
        assert "<math" in law and "$$" not in law and "``" not in law and ":class:" not in law
    adaptive = next(law for law in laws if "Slotine" in law and "Gamma" in law)
    assert re.search(r'<annotation encoding="application/x-tex">[^<]*\\Gamma\\, Y\^\\top s', adaptive)
    evidence = "".join(re.findall(r"<pre>(.*?)</pre>", text, re.DOTALL))
    assert "[[" not in evidence
    assert not re.search(r"\[\s*-?\d+\.\d+\s+-?\d", evidence)  # no "[0.1  0.2" numpy rows


@pytest.mark.browser
def test_index_html_images_tables_and_animation_in_chromium(report_dir: Path) -> None:
    """Every image decodes, the tables have their rows, the animation link opens a scene."""
    require_chromium()
    n = len(REPORT_CONTROLLERS)
    with start_chromium(1280, 900) as driver:
        driver.get((report_dir / "index.html").as_uri())
        images = driver.execute_script(
            "return Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth]);"
        )
        assert len(images) >= 4 + 5 * n
        broken = [src for src, complete, width in images if not (complete and width > 0)]
        assert broken == []
        rows = driver.execute_script(
            "const n = id => document.querySelectorAll('#' + id + ' tbody tr').length;"
            "return {t1: n('table1'), rms: n('table2-rms'), rep: n('table2-report'), coef: n('coefficients')};"
        )
        assert rows == {"t1": 4, "rms": n, "rep": 5, "coef": 11}
        first_cells = driver.execute_script(
            "return Array.from(document.querySelectorAll('#table2-rms tbody tr td:first-child'))"
            ".map(td => td.textContent);"
        )
        assert first_cells == list(REPORT_CONTROLLERS)
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


def test_a_sixth_law_gets_its_own_section_and_the_errata_use_the_runs_lambda(tmp_path: Path) -> None:
    """--controller adds the tutorial's law beside pd and adaptive; λ = 3 appears in the errata
    text (the page may not contradict the run's settings)."""
    options = ReportOptions(
        run=RunSpec(simulation=SimulationConfig(duration=1.0), lam=3.0),
        workers=1,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        animation=False,
        identification=False,  # its table is the test above's
        controllers=("pd", "adaptive", "examples/sliding_mode.py:SlidingMode"),
    )
    results = build_report(tmp_path / "r", options)
    assert list(results["controllers"]) == ["pd", "adaptive", "sliding-mode"]
    settings = next(e for e in results["errata"] if e["topic"].startswith("Unstated"))
    assert "λ = 3 1/s" in settings["correct"]
    html = (tmp_path / "r" / "index.html").read_text()
    assert "id='ctrl-sliding-mode'" in html or 'id="ctrl-sliding-mode"' in html
    assert results["controllers"]["sliding-mode"]["figures"]


def test_another_robot_gets_the_pipeline_without_the_reports_sections(tmp_path: Path) -> None:
    """On the double pendulum: no Table 1, no report Table 2, no closed-form check, no errata."""
    from twolink_pin.model import example_robot_urdf

    urdf = str(example_robot_urdf("double_pendulum_description/urdf/double_pendulum.urdf"))
    options = ReportOptions(
        robot=urdf,
        run=RunSpec(simulation=SimulationConfig(duration=1.0)),
        workers=1,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        animation=False,
        controllers=("pd",),
    )
    results = build_report(tmp_path / "r", options)
    assert results["twolink"] is None and results["errata"] == []
    assert results["robot"]["equations"]["shown"]  # its own derived equations, no course beside them
    html = (tmp_path / "r" / "index.html").read_text()
    assert 'id="equations-M"' in html and 'id="equations-course"' not in html
    assert "table1" not in html and "table2-report" not in html and "Errata" not in html
    # the sections it has are numbered 1, 2, 3 ... with no gap where the report's would be
    numbers = [int(n) for n in re.findall(r'<h2 id="[^"]+">(\d+)\. ', html)]
    assert numbers == list(range(1, 7)), numbers
    nav = re.search(r"<nav>(.*?)</nav>", html, re.S)
    assert nav is not None and re.findall(r'">(\d+) ', nav[1]) == [str(n) for n in numbers]


def test_what_the_report_shows_of_a_robot_is_its_profiles_declaration(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A catalog robot whose profile declares two report laws and the animated one: the
    report runs those (not every built-in law), animates the declared one, and with
    ``--plant-friction on`` every law's row says it ran on a plant with friction."""
    from dataclasses import replace

    from twolink_pin.model import catalog, example_robot_urdf
    from twolink_pin.model.profile import ReportProfile, generic_profile
    from twolink_pin.run_spec import PlantOptions

    urdf = example_robot_urdf("double_pendulum_description/urdf/double_pendulum.urdf")
    profile = replace(
        generic_profile(urdf),
        name="declared",
        friction=((0.1, 0.1), (0.05, 0.05)),
        report=ReportProfile(laws=("pd", "computed-torque"), animated_law="computed-torque"),
    )
    monkeypatch.setitem(catalog.CATALOG, "declared", lambda: (urdf, profile))
    options = ReportOptions(
        robot="declared",
        run=RunSpec(simulation=SimulationConfig(duration=0.5), plant=PlantOptions(friction="on")),
        workers=1,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        animation=False,
    )
    results = build_report(tmp_path / "r", options)
    assert list(results["controllers"]) == ["pd", "computed-torque"]
    assert results["animated"] == "computed-torque"
    assert results["comparison"]["plants"] == {"pd": "friction", "computed-torque": "friction"}
    assert results["twolink"] is None and results["errata"] == [] and results["identification"] is None
    html = (tmp_path / "r" / "index.html").read_text()
    assert re.search(r"<tr><td>pd</td><td>friction</td>", html)


def test_the_identification_section_can_be_left_out(tmp_path: Path, report_dir: Path) -> None:
    """--no-identification (ReportOptions.identification=False): no section, no link in the
    navigation, no entry in results.json; left in (the module's 4-s report, shorter than an
    excitation period like a 1-s one), the report still has its table."""
    short = {
        "run": RunSpec(simulation=SimulationConfig(duration=1.0)),
        "workers": 1,
        "limits_section": False,
        "sim_to_sim": False,
        "animation": False,
        "controllers": ("pd",),
    }
    results = build_report(tmp_path / "without", ReportOptions(identification=False, **short))
    html = (tmp_path / "without" / "index.html").read_text()
    assert results["identification"] is None and 'id="identification"' not in html
    assert 'href="#identification"' not in html
    assert SHORT.identification and SHORT.run.simulation.duration < 10.0  # one excitation period
    results = json.loads((report_dir / "results.json").read_text())
    html = (report_dir / "index.html").read_text()
    assert (
        results["identification"]["table"]
        and 'id="identification"' in html
        and 'href="#identification"' in html
    )


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

    import twolink_pin.report.pages as pages

    def boom(*args: object, **kwargs: object) -> None:
        raise RuntimeError("disk full")

    monkeypatch.setattr(pages, "write_pages", boom)
    small = ReportOptions(  # the smallest report that still goes through every stage before the pages
        run=RunSpec(simulation=SimulationConfig(duration=0.5)),
        workers=1,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        animation=False,
        identification=False,
        controllers=("pd",),
    )
    with pytest.raises(RuntimeError, match="disk full"):
        build_report(out, small)
    assert (out / "index.html").read_text() == "previous report"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging directory left behind


def test_a_diverging_run_in_a_worker_is_a_section_and_the_others_are_written(tmp_path: Path) -> None:
    """λ = 1e6 makes the Slotine–Li laws diverge in the worker processes: each is an entry saying
    when (the exception pickles), the laws without λ (pd) are in the tables, the page is written."""
    options = ReportOptions(
        run=RunSpec(simulation=SimulationConfig(duration=0.5), lam=1e6),
        workers=2,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        animation=False,
        identification=False,
    )
    results = build_report(tmp_path / "out", options)
    assert results["failed"] and set(results["failed"]) <= set(REPORT_CONTROLLERS)
    assert all("diverged at t = " in what for what in results["failed"].values())
    assert "pd" in results["controllers"] and "pd" not in results["failed"]
    html = (tmp_path / "out" / "index.html").read_text()
    for name in results["failed"]:
        assert f'id="ctrl-{name}"' in html
    assert "did not finish" in html


def test_a_missing_mesh_costs_the_animation_not_the_report(tmp_path: Path) -> None:
    """A URDF whose mesh file is missing: the report is written, with a note naming the mesh
    where the animation would be, and the warning in results.json (the CLI prints it)."""
    import shutil

    urdf = tmp_path / "missing_mesh.urdf"
    shutil.copy(Path(__file__).parent / "corpus" / "urdf" / "missing_mesh.urdf", urdf)
    options = ReportOptions(
        robot=str(urdf),
        run=RunSpec(simulation=SimulationConfig(duration=0.5)),
        workers=1,
        limits_section=False,  # its own tests: test_report_within_limits.py
        sim_to_sim=False,  # its own tests: test_report_sim_to_sim.py
        controllers=("pd",),
    )
    results = build_report(tmp_path / "r", options)
    assert results["animation"] is None and "pd" in results["controllers"]
    assert len(results["warnings"]) == 1 and "nothere.stl" in results["warnings"][0]
    html = (tmp_path / "r" / "index.html").read_text()
    assert "nothere.stl" in html and not (tmp_path / "r" / "animation.html").exists()


def test_a_report_without_an_adaptive_law_has_no_section_about_one_and_captions_its_figures(
    tmp_path: Path,
) -> None:
    """``--controller mpc --controller pd`` (here pd alone): the identification section answers
    why an adaptive law's p̂ is still far from p — without one it is not there (it was); every
    figure's caption says what it shows (the figure's title), its file name beside it."""
    from twolink_pin.report.pages import figure_captions

    options = ReportOptions(
        run=RunSpec(simulation=SimulationConfig(duration=0.5)),
        workers=1,
        limits_section=False,
        animation=False,
        controllers=("pd",),
    )  # identification asked for (the default)
    results = build_report(tmp_path / "r", options)
    html = (tmp_path / "r" / "index.html").read_text()
    assert results["identification"] is None and "still far" not in html and 'id="identification"' not in html
    captions = figure_captions(tmp_path / "r" / "figures")
    assert "pd_theta1.png" in captions and "joint 1 position" in captions["pd_theta1.png"]
    for name, caption in captions.items():
        assert (
            f'<figcaption>{caption.replace("&", "&amp;")} <span class="file">({name})</span>'
            in html.replace("&#39;", "'")
        )
    assert "$" not in "".join(captions.values())  # mathtext made plain
