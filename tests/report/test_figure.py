"""Figure helpers, seen through matplotlib's public interfaces: a new figure is on an Agg canvas
whose renderer the tight layout and the PNG share; the tight layout leaves no layout engine, so
saving draws the figure once (one ``draw_event``), into the same pixels as matplotlib's own
``tight_layout``; integer ticks are whole numbers."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread

from tests.helpers.images import distinct_colours
from vo_doppler.report.figure import integer_ticks, new_figure, tight_layout


def _figure():
    fig = new_figure(figsize=(6, 3))
    ax = fig.subplots()
    ax.plot(np.arange(50.0), np.sin(np.arange(50.0) / 5.0), label="a sine")
    ax.set_xlabel("time since first GNSS epoch [s]")
    ax.set_ylabel("heading error\n(estimate − truth) [deg]")
    ax.legend(fontsize=8)
    ax.set_title("a title")
    return fig


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


def _drawn_with(fig) -> list:
    """The renderer of every ``draw_event`` the figure sends from now on."""
    renderers = []
    fig.canvas.mpl_connect("draw_event", lambda event: renderers.append(event.renderer))
    return renderers


def test_tight_layout_leaves_no_layout_engine_and_saving_draws_once():
    fig = _figure()
    tight_layout(fig)
    draws = _drawn_with(fig)
    _png(fig)
    assert fig.get_layout_engine() is None
    assert len(draws) == 1
    # matplotlib's own tight layout leaves an engine that draws the figure once more
    theirs = _figure()
    theirs.tight_layout()
    their_draws = _drawn_with(theirs)
    _png(theirs)
    assert len(their_draws) == 2


def test_tight_layout_gives_the_layout_and_pixels_of_matplotlibs():
    ours = _figure()
    tight_layout(ours)
    theirs = _figure()
    theirs.tight_layout()
    params = ("left", "right", "bottom", "top")
    assert [getattr(ours.subplotpars, p) for p in params] == [
        getattr(theirs.subplotpars, p) for p in params
    ]
    assert ours.subplotpars.left > 0.1
    png = _png(ours)
    assert png == _png(theirs)
    pixels = imread(io.BytesIO(png), format="png")
    assert pixels.shape == (300, 600, 4)  # 6 x 3 in at 100 dpi, RGBA
    assert distinct_colours(pixels) > 10  # drawn, not blank


def test_the_layout_and_the_png_share_the_canvas_renderer():
    fig = _figure()
    layout_renderer = fig.canvas.get_renderer()
    tight_layout(fig)
    draws = _drawn_with(fig)
    assert _png(fig).startswith(b"\x89PNG")
    assert draws == [layout_renderer]
    assert fig.canvas.get_renderer() is layout_renderer


def test_integer_ticks_are_whole_numbers():
    fig = new_figure(figsize=(4, 3))
    ax = fig.subplots()
    ax.plot([0.0, 1.0], [0.0, 2.6])
    integer_ticks(ax.yaxis)
    ticks = ax.yaxis.get_ticklocs()
    assert len(ticks) >= 2
    np.testing.assert_array_equal(ticks, np.round(ticks))
    # without it, the same axis gets fractional ticks
    assert np.any(ax.xaxis.get_ticklocs() != np.round(ax.xaxis.get_ticklocs()))


@pytest.mark.parametrize("channels", [3, 4])
def test_distinct_colours_counts_the_distinct_pixels(channels):
    """The packed count of tests/helpers/images.py equals the count of distinct rows, for 8-bit
    images and for the float images matplotlib decodes (levels / 255)."""
    rng = np.random.default_rng(channels)
    levels = rng.integers(0, 4, size=(40, 50, channels)).astype(np.uint8) * 85
    expected = len(np.unique(levels.reshape(-1, channels), axis=0))
    assert 2 < expected <= 4**channels
    assert distinct_colours(levels) == expected
    assert distinct_colours(levels.astype(np.float32) / 255.0) == expected
    assert distinct_colours(np.zeros((5, 5, channels), np.uint8)) == 1
