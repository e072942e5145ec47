"""The images the README and docs/ show: each exists, decodes, has a sensible size and
real content (not blank), is made by ``scripts/docs_images.py`` from the current code, and
every file in docs/images/ is shown somewhere. Regenerating them all takes minutes and a
browser (``.venv/bin/python scripts/docs_images.py``); one cheap maker runs here."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
SCRIPT = ROOT / "scripts" / "docs_images.py"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
REFERENCE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)|<img[^>]*\ssrc=\"([^\"]+)\"")


def referenced_images() -> dict[Path, list[str]]:
    """Image file → the pages that show it (local images only)."""
    found: dict[Path, list[str]] = {}
    for page in PAGES:
        for match in REFERENCE.finditer(page.read_text(encoding="utf-8")):
            target = match[1] or match[2]
            if re.match(r"[a-z]+:", target):
                continue
            found.setdefault((page.parent / target).resolve(), []).append(page.name)
    return found


IMAGE_FILES = sorted(referenced_images())


def test_pages_show_the_expected_images() -> None:
    """The README shows the report and both animations; the site's pages their figures."""
    names = {p.name for p in IMAGE_FILES}
    assert {
        "report.png",
        "animation.png",
        "live.png",
        "trajectory_workspace.png",
        "adaptive_theta1.png",
    } <= names


@pytest.mark.parametrize("path", IMAGE_FILES, ids=[p.name for p in IMAGE_FILES])
def test_image_exists_decodes_and_is_not_blank(path: Path) -> None:
    """A PNG of 300–2500 × 200–2000 px whose pixels vary (grey-level standard deviation above
    12 of 255) with at least 40 distinct colours (at 5 bits per channel)."""
    assert path.is_file(), f"{path.relative_to(ROOT)} is shown by {referenced_images()[path]} but missing"
    with Image.open(path) as image:
        assert image.format == "PNG"
        image.load()
        width, height = image.size
        rgb = np.asarray(image.convert("RGB"), dtype=np.uint8)
    assert 300 <= width <= 2500 and 200 <= height <= 2000, (width, height)
    grey = rgb.astype(float).mean(axis=2)
    assert grey.std() > 12, f"{path.name} looks blank: grey std {grey.std():.1f}"
    colours = np.unique((rgb >> 3).reshape(-1, 3), axis=0)
    assert len(colours) >= 40, f"{path.name} has only {len(colours)} colours"


def test_every_image_is_shown_and_made_by_a_script() -> None:
    """No stale file in docs/images/ (each is shown by a page), and each is written by a
    script of scripts/ (its name, or its family ``prefix_*.png``, appears there:
    docs_images.py for the README's and the general pages', identification_docs.py for
    ``identification_*.png``), so none is a hand-made shot."""
    on_disk = {p.resolve() for p in IMAGES.glob("*.png")}
    assert on_disk - set(IMAGE_FILES) == set()
    scripts = "".join(p.read_text(encoding="utf-8") for p in sorted((ROOT / "scripts").glob("*.py")))
    made = [p.name for p in IMAGE_FILES if p.name in scripts or f"{p.name.split('_')[0]}_*.png" in scripts]
    assert sorted(p.name for p in IMAGE_FILES if p.name not in made) == []


def _script() -> object:
    spec = importlib.util.spec_from_file_location("docs_images", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_script_lists_its_makers(capsys: pytest.CaptureFixture[str]) -> None:
    """``--help`` runs without a browser and names every maker."""
    script = _script()
    with pytest.raises(SystemExit) as done:
        script.main(["--help"])  # type: ignore[attr-defined]
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert all(name in out for name in ("report", "animation", "live", "figures", "ur5_square"))


@pytest.mark.slow
def test_figures_maker_writes_decodable_figures(tmp_path: Path) -> None:
    """The browser-free maker (a 30-s adaptive run and the trajectory figures) writes its two
    images with the names the pages show, into ``--out``."""
    _script().main(["figures", "--out", str(tmp_path)])  # type: ignore[attr-defined]
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == ["adaptive_theta1.png", "trajectory_workspace.png"]
    for name in written:
        test_image_exists_decodes_and_is_not_blank(tmp_path / name)
