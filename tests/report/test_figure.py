"""Figure helpers: a new figure is on an Agg canvas whose renderer the tight layout and the PNG
share; the tight layout leaves no layout engine, so saving draws the figure once, into the same
pixels as matplotlib's own ``tight_layout``."""

from __future__ import annotations

import io

import numpy as np

from vo_doppler.report.figure import new_figure, tight_layout


def _figure():
    fig = new_figure(figsize=(6, 3))
    ax = fig.subplots()
    (line,) = ax.plot(np.arange(50.0), np.sin(np.arange(50.0) / 5.0), label="a sine")
    ax.set_xlabel("time since first GNSS epoch [s]")
    ax.set_ylabel("heading error\n(estimate − truth) [deg]")
    ax.legend(fontsize=8)
    ax.set_title("a title")
    return fig, line


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


def test_tight_layout_leaves_no_layout_engine_and_saving_draws_once():
    fig, line = _figure()
    tight_layout(fig)
    draws = []
    draw = line.draw
    line.draw = lambda renderer: (draws.append(renderer), draw(renderer))
    _png(fig)
    assert fig.get_layout_engine() is None
    assert len(draws) == 1


def test_tight_layout_gives_the_layout_and_pixels_of_matplotlibs():
    ours, _ = _figure()
    tight_layout(ours)
    theirs, _ = _figure()
    theirs.tight_layout()
    params = ("left", "right", "bottom", "top")
    assert [getattr(ours.subplotpars, p) for p in params] == [
        getattr(theirs.subplotpars, p) for p in params
    ]
    assert ours.subplotpars.left > 0.1
    assert _png(ours) == _png(theirs)


def test_the_layout_and_the_png_share_the_canvas_renderer():
    fig, _ = _figure()
    tight_layout(fig)
    layout_renderer = fig.canvas.renderer
    png = _png(fig)
    assert png.startswith(b"\x89PNG")
    assert fig.canvas.renderer is layout_renderer
