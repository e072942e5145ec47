"""MkDocs hook: the tutorial page is ``examples/tutorial.ipynb``, executed when the site is built.

The notebook is run top to bottom by nbclient on a fresh ``python3`` kernel (ipykernel,
the build's own interpreter), in a temporary working directory; a cell that raises fails
the build. The page then shows exactly what that run produced: markdown cells as they
are (their ``$…$`` math becomes MathML like every page's), code cells highlighted,
printed text, the matplotlib figures as PNG files beside the page (``tutorial/…png``)
and HTML outputs, the embedded meshcat animation among them, as they are. The committed
notebook (without outputs) and its jupytext twin ``examples/tutorial.py`` are published
beside the page for download.

Set ``TWOLINK_PIN_EXECUTED_TUTORIAL`` to the path of an already executed copy to show it
instead of running the notebook again (the test suite does so: the notebook it has just
run is the one the site shows).
"""

from __future__ import annotations

import base64
import logging
import os
import re
import tempfile
import time
from pathlib import Path
from typing import Any

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File, Files
from mkdocs.structure.pages import Page

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "examples" / "tutorial.ipynb"
SCRIPT = ROOT / "examples" / "tutorial.py"
PAGE = "tutorial.md"
EXECUTED_ENV = "TWOLINK_PIN_EXECUTED_TUTORIAL"
TIMEOUT = 600  # [s] per cell
LOG = logging.getLogger("mkdocs.hooks.tutorial_page")

_raw_outputs: dict[str, str] = {}


def execute_notebook(path: Path = NOTEBOOK, timeout: float = TIMEOUT) -> Any:
    """``path`` run top to bottom on a fresh kernel (the ``python3`` kernel of this
    interpreter, over IPC sockets) in a temporary directory: the executed notebook
    (nbformat v4). Raises nbclient's ``CellExecutionError`` naming the cell."""
    import nbformat
    from jupyter_client.manager import KernelManager
    from nbclient import NotebookClient

    notebook = nbformat.read(path, as_version=4)
    with tempfile.TemporaryDirectory(prefix="twolink-tutorial-") as workdir:
        # IPC sockets in the working directory: no TCP port, nothing reachable from outside
        kernel = KernelManager(kernel_name="python3", transport="ipc", ip=str(Path(workdir) / "kernel"))
        client = NotebookClient(
            notebook, km=kernel, timeout=timeout, resources={"metadata": {"path": workdir}}
        )
        try:
            client.execute()
        finally:
            if kernel.has_kernel:  # nbclient leaves a kernel it did not create running
                kernel.shutdown_kernel()
    return notebook


def _executed() -> Any:
    import nbformat

    given = os.environ.get(EXECUTED_ENV)
    if given:
        LOG.info(f"tutorial: showing the executed notebook {given}")
        return nbformat.read(given, as_version=4)
    start = time.monotonic()
    try:
        notebook = execute_notebook()
    except Exception as error:  # CellExecutionError, a dead kernel, a timeout
        raise PluginError(f"{NOTEBOOK.relative_to(ROOT)} failed to run: {error}") from None
    LOG.info(f"tutorial: executed {NOTEBOOK.relative_to(ROOT)} in {time.monotonic() - start:.1f} s")
    return notebook


def _text_block(text: str) -> str:
    fence = "`" * max(3, 1 + max((len(r) for r in re.findall(r"`+", text)), default=0))
    return f"{fence}text\n{text.rstrip()}\n{fence}"


def notebook_markdown(notebook: Any) -> tuple[str, dict[str, bytes], dict[str, str]]:
    """The page's Markdown, its images ``{path: PNG bytes}`` and its raw HTML outputs
    ``{placeholder: HTML}`` (put in after the Markdown is converted)."""
    parts = [
        "<!-- Generated from examples/tutorial.ipynb by docs/hooks/tutorial_page.py. -->",
    ]
    images: dict[str, bytes] = {}
    raw: dict[str, str] = {}
    note = (
        '!!! note "This page is a notebook, run when the site was built"\n'
        "    Download [tutorial.ipynb](tutorial.ipynb) (or its plain-script twin "
        "[tutorial.py](tutorial.py)) and run it top to bottom: `pip install -e '.[docs]'` "
        "brings Jupyter's kernel; `jupyter lab examples/tutorial.ipynb` or VS Code opens it. "
        "Every output below is from that run."
    )
    for index, cell in enumerate(notebook.cells):
        if cell.cell_type == "markdown":
            parts.append(cell.source.replace("](../docs/", "]("))  # the notebook's links, from docs/
            if index == 0:
                parts.append(note)
            continue
        if cell.cell_type != "code":
            continue
        parts.append(f"```python\n{cell.source.rstrip()}\n```")
        outputs: list[str] = []
        stream: list[str] = []  # consecutive printed text, one block
        for k, output in enumerate(cell.get("outputs", [])):
            kind = output.output_type
            if kind == "error":
                raise PluginError(f"tutorial: cell {index} raised {output.ename}: {output.evalue}")
            if kind == "stream":
                stream.append(output.text)
                continue
            if stream:
                outputs.append(_text_block("".join(stream)))
                stream = []
            data = output.get("data", {})
            if "text/html" in data:
                key = f"NOTEBOOKOUTPUT{index}X{k}"
                raw[key] = data["text/html"]
                outputs.append(key)
            elif "image/png" in data:
                name = f"tutorial/cell-{index}-{k}.png"
                images[name] = base64.b64decode(data["image/png"])
                outputs.append(f"![Output of cell {index}]({name})")
            elif "text/plain" in data:
                outputs.append(_text_block(data["text/plain"]))
        if stream:
            outputs.append(_text_block("".join(stream)))
        if outputs:
            parts.append('<div class="notebook-output" markdown>\n\n' + "\n\n".join(outputs) + "\n\n</div>")
    return "\n\n".join(parts) + "\n", images, raw


def on_files(files: Files, config: MkDocsConfig) -> Files:
    markdown, images, raw = notebook_markdown(_executed())
    _raw_outputs.clear()
    _raw_outputs.update(raw)
    files.append(File.generated(config, PAGE, content=markdown))
    for name, png in images.items():
        files.append(File.generated(config, name, content=png))
    files.append(File.generated(config, "tutorial.ipynb", abs_src_path=str(NOTEBOOK)))
    files.append(File.generated(config, "tutorial.py", abs_src_path=str(SCRIPT)))
    return files


def on_page_content(html: str, page: Page, config: MkDocsConfig, files: Files) -> str:
    if page.file.src_uri != PAGE:
        return html
    for key, output in _raw_outputs.items():
        placeholder = f"<p>{key}</p>"
        if placeholder not in html:
            raise PluginError(f"tutorial: the output {key} was lost on the way to HTML")
        html = html.replace(placeholder, f'<div class="notebook-html">{output}</div>')
    return html
