"""Rendering with one mathtext parser and one text-size cache per process (``plotting/_save.py``):
a figure drawn after others, reading their parses and text sizes from the shared caches, is the
same file, byte for byte, as the figure drawn with matplotlib's own parser and cache; and a
renderer whose parser is of another kind keeps its own."""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

import pytest
from matplotlib.figure import Figure
from matplotlib.mathtext import MathTextParser

from twolink_pin.plotting import _save
from twolink_pin.plotting._style import Margins, fix_margins, new_figure

LABELS = (r"$\theta_{1}$ [rad]", r"$\dot\theta_{1}$ [rad/s]", r"$e_{1} = \theta_{1} - \theta_{1,d}$")


def _figure(dpi: float, fontsize: float, labels: tuple[str, ...] = LABELS) -> Figure:
    """Two panels whose axis labels, titles, legend and suptitle are mathtext: each label at
    ``fontsize`` [pt] and in the legend's smaller size."""
    fig = new_figure((4.0, 3.2))
    fig.set_dpi(dpi)
    axes = fig.subplots(2, 1, sharex=True)
    for k, ax in enumerate(axes):
        ax.plot([0.0, 1.0, 2.0], [0.0, k + 1.0, 0.5], label=labels[k])
        ax.plot([0.0, 2.0], [1.0, 0.0], ls="--", label=labels[2])
        ax.set_ylabel(labels[k], fontsize=fontsize)
        ax.set_title(labels[2], fontsize=fontsize)
        ax.legend(loc="upper right", fontsize=7)
    fig.suptitle(rf"joint 1: {labels[0]} and $\hat{{p}}_{{2}} - p_{{2}}$", fontsize=fontsize)
    fix_margins(fig, Margins(left=0.7, right=0.1, bottom=0.4, top=0.5, hspace=0.4))
    return fig


def _parser(fig: Figure) -> object:
    return _save.figure_renderer(fig).mathtext_parser


def test_a_figure_drawn_with_the_shared_parser_is_the_file_drawn_with_its_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each figure is drawn with matplotlib's own parser (a new one per renderer, nothing lent),
    then after the others with the process's parser they filled: same resolution and fonts, or
    another resolution, other font sizes, other labels."""
    kinds = {
        "same": (110.0, 10.0, LABELS),
        "dpi": (73.0, 10.0, LABELS),
        "size": (110.0, 8.5, LABELS),
        "labels": (110.0, 10.0, (r"$\tau_{1}$ [N·m]", LABELS[1], r"$|e_{1}|$ [rad]")),
    }
    with monkeypatch.context() as own:
        own.setattr(_save, "_PLAIN", {"no": "parser has these settings"})  # nothing is replaced
        alone = {}
        for key, kind in kinds.items():
            fig = _figure(*kind)
            assert type(_parser(fig)) is MathTextParser, key
            alone[key] = _save.save_figure(fig, tmp_path / f"alone_{key}.png").read_bytes()

    monkeypatch.setattr(_save, "_SHARED", [])
    monkeypatch.setattr(_save, "_METRICS", {})
    first = _figure(*kinds["same"])
    _save.save_figure(first, tmp_path / "first.png")
    cache = _save._matplotlib_metrics_cache()
    assert cache is not None  # this matplotlib's per-renderer cache is as expected
    for key, kind in kinds.items():
        fig = _figure(*kind)
        assert _parser(fig) is _parser(first) is _save._SHARED[0], key  # the parser is shared …
        renderer, first_renderer = fig.canvas.get_renderer(), first.canvas.get_renderer()  # type: ignore[attr-defined]
        # … and so is the text-size cache, between renderers of one resolution only
        assert (cache[renderer] is cache[first_renderer]) == (kind[0] == kinds["same"][0]), key
        shared = _save.save_figure(fig, tmp_path / f"shared_{key}.png").read_bytes()
        assert shared == alone[key], key  # … and the file is the same
    assert len(_save._METRICS) == 2  # the two resolutions
    hits = sum(metrics.cache_info().hits for _, metrics in _save._METRICS.values())
    assert hits > 0  # the figures after the first read sizes the first measured


def test_a_parser_of_another_kind_is_kept() -> None:
    """A renderer whose parser makes another output (raster), or is of another type, keeps it."""

    class Other(MathTextParser):  # as the renderer's own, subclassed
        pass

    for parser in (MathTextParser("agg"), Other("path")):
        fig = _figure(110.0, 10.0)
        fig.canvas.get_renderer().mathtext_parser = parser  # type: ignore[attr-defined]
        assert _parser(fig) is parser


def _draw_in_child(folder: str) -> None:
    """In a forked child: how many parsers and text-size caches it inherited, then the figure drawn."""
    Path(folder, "inherited.txt").write_text(f"{len(_save._SHARED)} {len(_save._METRICS)}")
    _save.save_figure(_figure(110.0, 10.0), Path(folder, "child.png"))


@pytest.mark.skipif(not hasattr(os, "register_at_fork"), reason="a platform that does not fork")
def test_a_forked_child_draws_with_a_parser_of_its_own(tmp_path: Path) -> None:
    """A child forked after the parent has drawn (a report worker forked by a process that drew
    figures) does not inherit the parser, whose kept parses hold the parent's fonts (FreeType
    failed on them in the child: "too many hints"); it draws the same file."""
    parent = _save.save_figure(_figure(110.0, 10.0), tmp_path / "parent.png").read_bytes()
    assert _save._SHARED and _save._METRICS  # the parent holds a parser and sizes of the figure
    child = multiprocessing.get_context("fork").Process(target=_draw_in_child, args=(str(tmp_path),))
    child.start()
    child.join(120.0)
    assert child.exitcode == 0
    assert (tmp_path / "inherited.txt").read_text() == "0 0"
    assert (tmp_path / "child.png").read_bytes() == parent
