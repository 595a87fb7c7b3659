"""New figures, with matplotlib loaded by the first one drawn rather than by importing the
report package (matplotlib with PIL and fonttools is about 28 MiB resident)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def new_figure(**kwargs: Any) -> Figure:
    """``matplotlib.figure.Figure(**kwargs)`` on an Agg canvas, outside pyplot's state: the
    tight layout and the PNG then share one renderer (and its text measurements) instead of
    one each from a canvas made for the occasion."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def tight_layout(fig: Figure) -> None:
    """``fig.tight_layout()`` without the placeholder layout engine it leaves behind, which
    makes every ``savefig`` lay out and draw the whole figure once more, unrendered, before
    drawing it."""
    fig.tight_layout()
    fig.set_layout_engine(None)


def integer_ticks(axis: Any) -> None:
    """Only whole-number ticks on a matplotlib ``axis`` (counts such as satellites)."""
    from matplotlib.ticker import MaxNLocator

    axis.set_major_locator(MaxNLocator(integer=True))
