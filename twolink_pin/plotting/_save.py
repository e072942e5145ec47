"""Rendering a figure and writing it: one draw on the figure's Agg canvas, a check that the
labels fit its fixed margins (else constrained layout and a second draw), the file written
atomically.

Every figure's renderer reads its mathtext (``$\\dot\\theta_{1}$``) with one parser per process
(:func:`figure_renderer`), which keeps :data:`KEPT_PARSES` parses. Matplotlib gives each new
renderer a parser of its own and keys its parse cache (50 parses, over all parsers) on the
parser, so each figure parsed again, with pyparsing, the labels the figures before it had
parsed (a sixth of a figure's drawing time). A parse depends only on the text, the font and
the resolution: the pixels are the same, byte for byte (``tests/test_plotting_render.py``).

Likewise the size of a text (a tick label's, a title's: ``get_text_width_height_descent``), which
matplotlib caches per renderer, so that each figure measured "0", "10" and "time [s]" again:
every Agg renderer of one resolution and one set of text settings reads one cache
(:func:`_share_text_metrics`). A figure is not cleared after it is saved (``Figure.clear``
builds the empty figure again, about a twentieth of the drawing time): a figure dropped is
collected with everything it holds.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib
import matplotlib.image
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.mathtext import MathTextParser, VectorParse
from matplotlib.text import Text
from matplotlib.transforms import Bbox

from twolink_pin.files import atomic_write
from twolink_pin.plotting._style import DPI
from twolink_pin.plotting.titles import shown_title

PNG_COMPRESS_LEVEL = 1
"""zlib level of the PNG writer: 1 encodes a figure in about half the time of the default 6
for files about 7 % larger."""


if TYPE_CHECKING:
    _PathParser = MathTextParser[VectorParse]  # generic in matplotlib's stubs only
else:
    _PathParser = MathTextParser

KEPT_PARSES = 1024
"""Mathtext parses the process keeps [count]: matplotlib keeps 50 over all its parsers, fewer
than the labels of a six-joint arm's figures (132 for three laws on the UR5)."""


class _KeptParses(_PathParser):
    """Matplotlib's parser of mathtext into glyphs and boxes (``"path"``, the Agg renderer's),
    keeping its last :data:`KEPT_PARSES` parses, keyed by what the parse reads: the text, the
    resolution, a copy of the font (a mutable object), antialiasing and hinting."""

    def __init__(self) -> None:
        super().__init__("path")
        self._kept = functools.lru_cache(maxsize=KEPT_PARSES)(self._parse)

    def parse(
        self, s: str, dpi: float = 72, prop: FontProperties | None = None, *, antialiased: bool | None = None
    ) -> VectorParse:
        rc = matplotlib.rcParams
        aa = rc["text.antialiased"] if antialiased is None else antialiased
        font = None if prop is None else prop.copy()
        return self._kept(s, dpi, font, aa, rc["text.hinting"], rc["text.hinting_factor"])

    def _parse(
        self, s: str, dpi: float, prop: FontProperties | None, aa: bool, *_hinting: object
    ) -> VectorParse:
        return super().parse(s, dpi, prop, antialiased=aa)


_SHARED: list[_KeptParses] = []
"""The process's parser (made by the first figure), lent to every renderer. A forked child
starts without it: its kept parses hold the parent's fonts, which FreeType cannot use across a
fork (matplotlib empties its own font cache in the child for the same reason; a report worker
drawing with them failed with "FT_Load_Glyph … too many hints")."""
if hasattr(os, "register_at_fork"):  # not on Windows, which does not fork
    os.register_at_fork(after_in_child=_SHARED.clear)
_PLAIN = vars(MathTextParser("path"))
"""The settings of a plain ``"path"`` parser: a renderer's parser is replaced only when it has them."""
_TEXT_SETTINGS = tuple(k for k in matplotlib.rcParams if k.startswith(("font.", "text.", "mathtext.")))
"""The settings a text's size depends on besides its own font and the resolution (the fonts each
family names, hinting, kerning, mathtext's fonts)."""
_METRICS: dict[str, tuple[list[RendererAgg], Any]] = {}
"""One text-size cache per resolution and text settings: the renderer it measures with (the
latest of them) and matplotlib's kind of cache around it. A forked child starts without them
(the renderer's parser holds the parent's fonts, as :data:`_SHARED`)."""
if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_METRICS.clear)


def _matplotlib_metrics_cache() -> Any:
    """Matplotlib's per-renderer text-size cache (``matplotlib.text._get_text_metrics_function``'s
    ``WeakKeyDictionary`` of renderer → cached function), or None if it is not one."""
    import weakref

    import matplotlib.text

    function = getattr(matplotlib.text, "_get_text_metrics_function", None)
    defaults: tuple[Any, ...] = getattr(function, "__defaults__", None) or ()
    cache = defaults[0] if len(defaults) == 1 else None
    return cache if isinstance(cache, weakref.WeakKeyDictionary) else None


def _share_text_metrics(renderer: RendererAgg) -> None:
    """Give ``renderer`` the text-size cache of every Agg renderer of its resolution and the
    current text settings (module docstring). A text's size is computed by the renderer as
    matplotlib's own cache does, with the latest renderer of the kind (a renderer's size in
    pixels does not enter it). A matplotlib whose cache is not as expected keeps its own."""
    cache = _matplotlib_metrics_cache()
    if cache is None or type(renderer) is not RendererAgg or renderer in cache:
        return
    rc = matplotlib.rcParams
    key = repr((renderer.dpi, tuple(rc[k] for k in _TEXT_SETTINGS)))
    entry = _METRICS.get(key)
    if entry is None:
        holder = [renderer]

        @functools.lru_cache(4096)  # matplotlib's own size, keyed as matplotlib keys it
        def metrics(text: str, fontprop: FontProperties, ismath: Any, dpi: float) -> Any:
            return holder[0].get_text_width_height_descent(text, fontprop, ismath)

        entry = _METRICS[key] = (holder, metrics)
    entry[0][0] = renderer  # measure with a live renderer of the kind (the latest)
    cache[renderer] = entry[1]


def figure_renderer(fig: Figure) -> RendererAgg:
    """``fig``'s Agg renderer (its canvas keeps one while the pixel size stays), reading mathtext
    with the process's parser (:class:`_KeptParses`) where its own is a plain ``"path"`` parser.
    A matplotlib whose renderer has no ``mathtext_parser``, or one of another kind or type,
    keeps its own: slower, the same pixels."""
    canvas = fig.canvas
    assert isinstance(canvas, FigureCanvasAgg)  # every figure here has its own (new_figure)
    renderer = canvas.get_renderer()
    parser = getattr(renderer, "mathtext_parser", None)
    if type(parser) is MathTextParser and vars(parser) == _PLAIN:
        if not _SHARED:
            _SHARED.append(_KeptParses())
        renderer.mathtext_parser = _SHARED[0]
        _share_text_metrics(renderer)  # its mathtext is measured with the shared parser too
    return renderer


def _drawn_labels(ax: Axes) -> list[Text]:
    """The texts around ``ax`` whose size depends on the data or the caller: its drawn tick
    labels, its axis labels, the axis offsets (``1e−3``) and its title."""
    texts = [ax.xaxis.label, ax.yaxis.label, ax.xaxis.offsetText, ax.yaxis.offsetText, ax.title]
    for axis, (lo, hi) in ((ax.xaxis, sorted(ax.get_xlim())), (ax.yaxis, sorted(ax.get_ylim()))):
        index = 0 if axis is ax.xaxis else 1
        for tick in axis.majorTicks:
            for label in (tick.label1, tick.label2):
                if label.get_visible() and lo <= label.get_position()[index] <= hi:
                    texts.append(label)
    return [t for t in texts if t.get_visible() and t.get_text()]


def _labels_fit(fig: Figure) -> bool:
    """After a draw: every tick label, axis label, offset and panel title lies inside the
    figure and outside every other panel's plotting area, and the suptitle overlaps none of
    them (1 px of rounding allowed)."""
    renderer = figure_renderer(fig)
    areas = [ax.get_window_extent() for ax in fig.axes]
    box = fig.bbox
    suptitle = fig._suptitle  # type: ignore[attr-defined]  # the Text of fig.suptitle, or None
    top = None
    if suptitle is not None and suptitle.get_text():
        top = suptitle.get_window_extent(renderer)
        areas.append(top)  # no panel's text may reach into it
    for k, ax in enumerate(fig.axes):
        for text in _drawn_labels(ax):
            extent = text.get_window_extent(renderer)
            if not (
                box.x0 - 1 <= extent.x0
                and extent.x1 <= box.x1 + 1
                and box.y0 - 1 <= extent.y0
                and extent.y1 <= box.y1 + 1
            ):
                return False
            inner = Bbox.from_extents(extent.x0 + 1, extent.y0 + 1, extent.x1 - 1, extent.y1 - 1)
            if any(i != k and inner.overlaps(area) for i, area in enumerate(areas)):
                return False
    return top is None or not any(top.overlaps(area) for area in areas[:-1])


def _lay_out_once(fig: Figure) -> None:
    """Run ``fig``'s layout engine once, then remove it: with a layout engine set, savefig
    draws the whole figure twice (a first pass with drawing disabled that runs the layout,
    then the real one). Same layout, same pixels (checked byte for byte)."""
    engine = fig.get_layout_engine()
    if engine is not None and fig.axes:
        engine.execute(fig)
        with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
            fig.set_layout_engine(None)  # None (not "none", a placeholder savefig still pre-draws for)


def save_figure(fig: Figure, path: Path) -> Path:
    """Render ``fig`` into ``path`` atomically (format from the suffix, PNG by default).

    The figure is drawn once on its Agg canvas (:func:`figure_renderer`); a figure with fixed :class:`Margins` whose
    labels do not fit (:func:`_labels_fit`) is then laid out by constrained layout and drawn
    again. A PNG's pixels are written as drawn (zlib level :data:`PNG_COMPRESS_LEVEL`); other
    formats go through ``savefig``. The file carries the figure's title
    (:func:`~twolink_pin.plotting.titles.shown_title`) as its ``Title``."""
    fmt = path.suffix[1:].lower() or "png"
    figure_renderer(fig)  # the layout and the draw below use it
    _lay_out_once(fig)
    canvas = fig.canvas
    assert isinstance(canvas, FigureCanvasAgg)  # every figure here has its own (new_figure)
    canvas.draw()
    if getattr(fig, "_twolink_margins", None) is not None and fig.axes and not _labels_fit(fig):
        fig.set_layout_engine("constrained")
        _lay_out_once(fig)
        canvas.draw()
    title = shown_title(fig)
    if fmt != "png":
        with atomic_write(path, "wb") as f:
            fig.savefig(f, format=fmt, dpi=DPI, metadata={"Title": title} if fmt in ("pdf", "svg") else None)
        return path
    with atomic_write(path, "wb") as f:
        matplotlib.image.imsave(
            f,  # type: ignore[arg-type]  # a binary file (mode "wb")
            canvas.buffer_rgba(),
            format="png",
            origin="upper",
            dpi=fig.dpi,
            metadata={"Title": title},
            pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL},
        )
    return path


def save_figures(figures: Mapping[str, Figure], out_dir: str | os.PathLike[str], prefix: str) -> list[Path]:
    """Save each figure as ``out_dir/<prefix><key>.png`` in order."""
    out = Path(out_dir)
    return [save_figure(fig, out / f"{prefix}{key}.png") for key, fig in figures.items()]
