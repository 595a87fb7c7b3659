"""New figures, with matplotlib loaded by the first one drawn rather than by importing the
report package (matplotlib with PIL and fonttools is about 28 MiB resident)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def new_figure(**kwargs: Any) -> Figure:
    """``matplotlib.figure.Figure(**kwargs)``: an Agg-rendered figure outside pyplot's state."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def integer_ticks(axis: Any) -> None:
    """Only whole-number ticks on a matplotlib ``axis`` (counts such as satellites)."""
    from matplotlib.ticker import MaxNLocator

    axis.set_major_locator(MaxNLocator(integer=True))
