"""MkDocs hook: the home page is the README, and links to repository files get a page.

* ``docs/index.md`` holds the line ``<!-- README.md -->``; it is replaced by the README
  (one text for the repository and the site), its links made relative to ``docs/``
  (``docs/model.md`` → ``model.md``, ``docs/images/…`` → ``images/…``, the tutorial
  notebook → its page, any other file ``path`` → ``../path``).
* A page's relative link to a file of the repository outside ``docs/`` (say
  ``../examples/sliding_mode.py``) points to a generated page ``source/<path>.md`` that
  shows the file, highlighted; a link to a missing file is left alone, so the strict
  build reports it.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files
from mkdocs.structure.pages import Page

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
MARKER = "<!-- README.md -->"
LINK = re.compile(r"(?P<open>\]\()(?P<target>[^)\s#]+)(?P<rest>[^)]*\))")
SITE_PAGES = {"examples/tutorial.ipynb": "tutorial.md", "examples/tutorial.py": "tutorial.md"}
"""README links to files that have their own page on the site."""
LANGUAGES = {".py": "python", ".toml": "toml", ".urdf": "xml", ".sh": "bash", ".yml": "yaml", ".json": "json"}


def readme_markdown() -> str:
    """README.md with its ``docs/`` links made relative to docs/."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")

    def relative_to_docs(match: re.Match[str]) -> str:
        target = match["target"]
        if target in SITE_PAGES:
            target = SITE_PAGES[target]
        elif target.startswith("docs/"):
            target = target.removeprefix("docs/")
        elif "://" not in target and not target.startswith(("/", "#", "mailto:")):
            target = "../" + target  # a repository file: from docs/, one folder up
        return match["open"] + target + match["rest"]

    return LINK.sub(relative_to_docs, text)


def _outside_target(page_src: str, target: str) -> Path | None:
    """The repository file a relative link of ``docs/<page_src>`` names, if outside docs/."""
    if "://" in target or target.startswith(("/", "mailto:")):
        return None
    path = (DOCS / page_src).parent.joinpath(target).resolve()
    if path.is_relative_to(DOCS) or not path.is_relative_to(ROOT) or not path.is_file():
        return None
    return path


def _pages_and_texts(files: Files) -> list[tuple[str, str]]:
    out = []
    for file in files.documentation_pages():
        text = readme_markdown() if file.src_uri == "index.md" else file.content_string
        out.append((file.src_uri, text))
    return out


def source_page_uri(path: Path) -> str:
    return f"source/{path.relative_to(ROOT).as_posix()}.md"


def _source_page(path: Path) -> str:
    text = path.read_text(encoding="utf-8")
    fence = "`" * max(3, 1 + max((len(r) for r in re.findall(r"`+", text)), default=0))
    language = LANGUAGES.get(path.suffix, "text")
    name = path.relative_to(ROOT).as_posix()
    return (
        f"# `{name}`\n\nThe file as it is in the repository.\n\n{fence}{language}\n{text.rstrip()}\n{fence}\n"
    )


def on_files(files: Files, config: MkDocsConfig) -> Files:
    wanted: set[Path] = set()
    for src, text in _pages_and_texts(files):
        for match in LINK.finditer(text):
            path = _outside_target(src, match["target"])
            if path is not None:
                wanted.add(path)
    for path in sorted(wanted):
        files.append(File.generated(config, source_page_uri(path), content=_source_page(path)))
    return files


def on_page_markdown(markdown: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    src = page.file.src_uri
    if src == "index.md":
        markdown = markdown.replace(MARKER, readme_markdown())
    depth = src.count("/")

    def relink(match: re.Match[str]) -> str:
        path = _outside_target(src, match["target"])
        if path is None:
            return match[0]
        return match["open"] + "../" * depth + source_page_uri(path) + match["rest"]

    return LINK.sub(relink, markdown)
