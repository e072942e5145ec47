"""The documentation site (``make docs``): it builds from the sources in strict mode, every
public name has its API entry, the laws' math is MathML, no page shows unconverted
reStructuredText or LaTeX, the tutorial page shows the executed notebook's own figures,
every docs page is in the navigation, and the site makes no network request.

The build is the one ``make docs`` runs (``mkdocs build --strict``, ~15 s), into a
temporary folder, showing the notebook ``tests/test_tutorial.py`` executed
(``tests/docs_build.py``).
"""

from __future__ import annotations

import base64
import html
import importlib
import pkgutil
import re
import time
import zlib
from pathlib import Path
from typing import Any

import pytest
import yaml
from browser import network_requests, require_chromium, start_chromium
from docs_build import ROOT, Site, built_site, executed_tutorial, hook

import twolink_pin

LAWS = ("PDFeedforward", "ComputedTorque", "WrongModel", "Adaptive", "AdaptiveFriction")


@pytest.fixture(scope="module")
def site() -> Site:
    built = built_site()
    if built.returncode != 0:
        pytest.fail(f"mkdocs build --strict failed:\n{built.output[-4000:]}", pytrace=False)
    return built


def _inventory(site: Site) -> dict[str, str]:
    """``objects.inv`` (Sphinx inventory v2, written by mkdocstrings): name → URI."""
    raw = (site.path / "objects.inv").read_bytes()
    header = raw.split(b"\n", 4)
    assert header[0] == b"# Sphinx inventory version 2"
    entries = {}
    for line in zlib.decompress(header[4]).decode("utf-8").splitlines():
        name, _role, _priority, uri, *_ = line.split(" ")
        entries[name] = uri.replace("$", name)
    return entries


def _public_modules() -> list[Any]:
    modules = [twolink_pin]
    for info in pkgutil.walk_packages(twolink_pin.__path__, "twolink_pin."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        modules.append(importlib.import_module(info.name))
    return modules


def test_site_builds_in_strict_mode(site: Site) -> None:
    """``mkdocs build --strict`` exits 0 (a broken link or anchor, a nav entry without a
    page, an unresolved cross-reference or a docstring griffe cannot parse would fail it)
    and writes a page per nav entry."""
    assert "WARNING" not in site.output, site.output[-3000:]
    for page in ("index", "tutorial", "model", "controllers", "api/index", "api/controllers"):
        assert (site.path / f"{page}.html").is_file(), page


def test_every_public_name_has_an_api_entry(site: Site) -> None:
    """Each name of ``twolink_pin.__all__`` and of every public module's ``__all__`` is in
    the site's inventory (an anchor on an API page), and so is every public module."""
    inventory = _inventory(site)
    missing = []
    for module in _public_modules():
        if module.__name__ not in inventory:
            missing.append(module.__name__)
        for name in getattr(module, "__all__", ()):
            if f"{module.__name__}.{name}" not in inventory:
                missing.append(f"{module.__name__}.{name}")
    assert missing == []
    assert len(twolink_pin.__all__) > 50
    page, anchor = inventory["twolink_pin.Adaptive"].split("#")
    assert page == "api/controllers.html" and f'id="{anchor}"' in (site.path / page).read_text()


def _section(page: str, anchor: str) -> str:
    """The HTML of the API entry ``anchor`` up to the next entry of the same level."""
    start = page.index(f'id="{anchor}"')
    level = page.rfind("<h", 0, start)
    tag = page[level : level + 3]
    end = page.find(f"{tag} ", start)
    return page[start : end if end > 0 else None]


def test_law_docstrings_render_their_math_as_mathml(site: Site) -> None:
    """Each control law's entry shows its law as a displayed MathML formula (with the LaTeX
    kept as an annotation), and its inline math too; no ``$`` is left."""
    page = (site.path / "api" / "controllers.html").read_text(encoding="utf-8")
    for law in LAWS:
        section = _section(page, f"twolink_pin.controllers.{law}")
        assert '<math alttext="\\tau = ' in section and 'display="block"' in section, law
        assert 'encoding="application/x-tex"' in section
        text = re.sub(r"<math.*?</math>", "", section, flags=re.DOTALL)
        assert "$" not in re.sub(r"<code.*?</code>", "", text, flags=re.DOTALL), law


def _prose(page: str) -> str:
    """A page's text outside code, math and scripts."""
    for pattern in (
        r"<script.*?</script>",
        r"<pre.*?</pre>",
        r"<code.*?</code>",
        r"<math.*?</math>",
        r"<iframe.*?</iframe>",
    ):
        page = re.sub(pattern, "", page, flags=re.DOTALL)
    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def test_no_page_shows_unconverted_markup(site: Site) -> None:
    """Outside code, no page shows a Sphinx role (``:func:`…```), an RST table border, a
    literal-block ``::`` or a LaTeX ``$…$`` (a ``$`` before a digit is a price): the docstrings' habits were converted."""
    bad = {}
    for path in sorted(site.path.rglob("*.html")):
        prose = _prose(path.read_text(encoding="utf-8"))
        found = re.findall(
            r":(?:func|class|meth|attr|data|mod|exc):`|^\s*={4,}\s+={4,}|\S::\s*$|\$[^$\s\d]", prose, re.M
        )
        if found:
            bad[str(path.relative_to(site.path))] = found[:3]
    assert bad == {}


def test_tutorial_page_shows_the_executed_notebooks_figures(site: Site) -> None:
    """The tutorial page's images are the PNG outputs of the run the tests made, byte for
    byte, and its animation is that run's iframe."""
    page = (site.path / "tutorial.html").read_text(encoding="utf-8")
    sources = re.findall(r'<img alt="Output of cell \d+" src="([^"]+)"', page)
    notebook = executed_tutorial().notebook
    outputs = [o for c in notebook.cells if c.cell_type == "code" for o in c.outputs]
    pngs = [base64.b64decode(o.data["image/png"]) for o in outputs if "image/png" in o.get("data", {})]
    assert len(sources) == len(pngs) == 2
    assert [(site.path / s).read_bytes() for s in sources] == pngs
    (frame,) = [o.data["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert frame in page
    assert (site.path / "tutorial.ipynb").read_bytes() == (ROOT / "examples" / "tutorial.ipynb").read_bytes()


def _nav_pages(nav: list[Any]) -> list[str]:
    pages = []
    for entry in nav:
        value = next(iter(entry.values())) if isinstance(entry, dict) else entry
        pages += _nav_pages(value) if isinstance(value, list) else [value]
    return pages


def test_every_docs_page_is_in_the_navigation() -> None:
    """Each ``docs/*.md`` and each generated page (tutorial, API pages) has a nav entry, and
    each API group of the hook has its page there."""
    nav = _nav_pages(yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))["nav"])
    on_disk = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    api = {f"api/{group[0]}.md" for group in hook("api_pages").GROUPS} | {"api/index.md"}
    assert on_disk - set(nav) == set()
    assert api | {"tutorial.md"} <= set(nav)
    assert len(nav) == len(set(nav))


def test_home_page_is_the_readme_with_working_links(site: Site) -> None:
    """index.html is the README: its docs/ links point at the site's pages and its images at
    the site's copies (strict mode checks they exist)."""
    page = (site.path / "index.html").read_text(encoding="utf-8")
    assert "Quick start" in page
    assert 'src="images/report.png"' in page and 'href="writing_a_controller.html"' in page
    assert "docs/" not in re.findall(r'href="([^"]+)"', page)


def test_site_loads_nothing_from_the_network_statically(site: Site) -> None:
    """No page's scripts, styles, images or frames come from another host (fonts are the
    system's, math is MathML): every ``src``/``href`` of those is relative or data:."""
    external = {}
    for path in site.path.rglob("*.html"):
        text = path.read_text(encoding="utf-8")
        text = re.sub(r'srcdoc="[^"]*"', "", text)  # the animation's page: checked in Chromium
        links = re.findall(
            r'<(?:script|img|iframe|source)[^>]* src="([^"]+)"|<link[^>]* href="([^"]+)"', text
        )
        found = [a or b for a, b in links if re.match(r"(https?:)?//", a or b)]
        if found:
            external[str(path.relative_to(site.path))] = found
    assert external == {}


@pytest.mark.browser
def test_pages_open_from_disk_without_a_network_request(site: Site) -> None:
    """The home page, a law's API entry and the tutorial (animation included), opened from
    ``file://`` in Chromium, request only file: and data: URLs; the tutorial's embedded
    scene loads."""
    require_chromium()
    with start_chromium(1200, 900) as driver:
        for page in ("index.html", "api/controllers.html", "tutorial.html"):
            network_requests(driver)
            driver.get((site.path / page).as_uri())
            time.sleep(0.5)
            if page == "tutorial.html":
                driver.switch_to.frame(driver.find_element("css selector", "iframe.twolink-pin-animation"))
                deadline = time.monotonic() + 30
                while not driver.execute_script("return window.sceneLoaded === true;"):
                    assert time.monotonic() < deadline, "the tutorial page's scene never loaded"
                    time.sleep(0.1)
                driver.switch_to.default_content()
            requests = network_requests(driver)
            assert requests, "no request recorded at all: the network log is not working"
            assert [u for u in requests if not u.startswith(("file:", "data:", "about:", "blob:"))] == [], (
                page
            )


def test_math_extension_leaves_code_alone() -> None:
    """The site's Markdown extension converts ``$…$`` and ``$$…$$`` to MathML but not inside
    code spans or fenced code, not prices (``$5 and $6``), and turns ``\\$`` into ``$``."""
    import markdown

    md = markdown.Markdown(extensions=[hook("math_markdown").MathExtension(), "fenced_code"])
    out = md.convert(
        "Law $a_1 * b_2$, `$x$`, \\$5, costs $5 and $6.\n\n$$\n\\tau = K s\n$$\n\n```\n$y$\n```\n"
    )
    assert out.count("<math") == 2 and 'display="block"' in out
    assert "<code>$x$</code>" in out and "$5, costs $5 and $6." in out and "$y$" in out
    assert "<em>" not in out  # the * inside the math is not emphasis


def test_griffe_extension_converts_rst_habits() -> None:
    """Roles become cross-references (or code when the target is private or external),
    ``::`` blocks fenced code, simple tables bullet lists, grouped Args one entry each."""
    rst = hook("griffe_rst")
    assert rst.convert_simple_tables("=====  ===\n``a``  one\n       more\n``b``  two\n=====  ===") == (
        "- ``a``: one more\n- ``b``: two"
    )
    assert (
        rst.convert_literal_blocks("Law::\n\n    tau = K s\n\nafter")
        == "Law:\n\n```text\ntau = K s\n```\n\nafter"
    )
    assert "```python" in rst.convert_literal_blocks("Use::\n\n    import numpy\n")
    grouped = rst.split_grouped_parameters("Args:\n    q, v: Angles [rad].\n        More.\n    x: One.\n")
    assert (
        grouped
        == "Args:\n    q: Angles [rad].\n        More.\n    v: Angles [rad].\n        More.\n    x: One.\n"
    )


def test_api_pages_cover_every_module_once() -> None:
    """The generated API pages name every public module in one ``:::`` directive, and no
    object twice (each public name is rendered once, on one page)."""
    pages = hook("api_pages").api_pages()
    directives = [
        line[4:] for text in pages.values() for line in text.splitlines() if line.startswith("::: ")
    ]
    assert len(directives) == len(set(directives))
    modules = {m.__name__ for m in _public_modules()}
    assert modules <= set(directives)


def test_notebook_markdown_keeps_every_output_kind(tmp_path: Path) -> None:
    """The tutorial hook turns a notebook into Markdown: printed text merged per cell, PNGs
    as files, HTML kept for later, and a cell error fails the build with its message."""
    import nbformat
    from mkdocs.exceptions import PluginError

    v4 = nbformat.v4
    cell = v4.new_code_cell(
        "x",
        outputs=[
            v4.new_output("stream", name="stdout", text="a\n"),
            v4.new_output("stream", name="stdout", text="b\n"),
            v4.new_output(
                "display_data",
                data={"image/png": base64.b64encode(b"PNG").decode(), "text/plain": "<Figure>"},
            ),
            v4.new_output("display_data", data={"text/html": "<b>hi</b>"}),
        ],
    )
    markdown, images, raw = hook("tutorial_page").notebook_markdown(
        v4.new_notebook(cells=[v4.new_markdown_cell("# T"), cell])
    )
    assert (
        "```text\na\nb\n```" in markdown
        and list(images.values()) == [b"PNG"]
        and list(raw.values()) == ["<b>hi</b>"]
    )
    broken = v4.new_code_cell(
        "1/0",
        outputs=[v4.new_output("error", ename="ZeroDivisionError", evalue="division by zero", traceback=[])],
    )
    with pytest.raises(PluginError, match="cell 0 raised ZeroDivisionError: division by zero"):
        hook("tutorial_page").notebook_markdown(v4.new_notebook(cells=[broken]))
