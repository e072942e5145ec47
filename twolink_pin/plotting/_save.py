"""Rendering a figure and writing it: one draw on the figure's Agg canvas, a check that the
labels fit its fixed margins (else constrained layout and a second draw), the file written
atomically.

"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import matplotlib
import matplotlib.image
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

from twolink_pin.files import atomic_write
from twolink_pin.plotting._style import DPI
from twolink_pin.plotting.titles import shown_title

PNG_COMPRESS_LEVEL = 1
"""zlib level of the PNG writer: 1 encodes a figure in about half the time of the default 6
for files about 7 % larger."""


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
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]  # the Agg canvas has one
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

    The figure is drawn once on its Agg canvas; a figure with fixed :class:`Margins` whose
    labels do not fit (:func:`_labels_fit`) is then laid out by constrained layout and drawn
    again. A PNG's pixels are written as drawn (zlib level :data:`PNG_COMPRESS_LEVEL`); other
    formats go through ``savefig``. The file carries the figure's title
    (:func:`~twolink_pin.plotting.titles.shown_title`) as its ``Title``."""
    fmt = path.suffix[1:].lower() or "png"
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
    """Save each figure as ``out_dir/<prefix><key>.png`` in order, then clear them all."""
    out = Path(out_dir)
    try:
        return [save_figure(fig, out / f"{prefix}{key}.png") for key, fig in figures.items()]
    finally:
        for fig in figures.values():
            fig.clear()
