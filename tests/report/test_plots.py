"""The top view of trajectories: one PNG, the chosen plane's coordinates on its axes, empty
trajectories left out."""

from __future__ import annotations

import numpy as np
from matplotlib.image import imread
from scipy.spatial.transform import Rotation

from tests.helpers.images import distinct_colours
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report import plots
from vo_doppler.report.plots import plot_top_view


def _line(points) -> Trajectory:
    points = np.asarray(points, dtype=float)
    return Trajectory(np.arange(len(points)), points, Rotation.identity(len(points)))


def test_the_top_view_is_a_png_of_its_figure_size(tmp_path):
    path = tmp_path / "top.png"
    plot_top_view({"a": _line([[0, 0, 0], [10, 5, 1]])}, path, title="a title")
    pixels = imread(path)
    assert pixels.shape[:2] == (660, 770)  # 7 x 6 in at 110 dpi
    assert distinct_colours(pixels) > 10


def test_each_trajectory_is_drawn_on_the_chosen_plane_with_its_start_and_end(monkeypatch, tmp_path):
    drawn = []
    figure = plots.new_figure

    def recorded(**kwargs):
        fig = figure(**kwargs)
        drawn.append(fig)
        return fig

    monkeypatch.setattr(plots, "new_figure", recorded)
    tracks = {"a": _line([[0, 0, 0], [10, 5, 1], [20, 5, 3]]), "empty": _line(np.zeros((0, 3)))}
    plot_top_view(tracks, tmp_path / "xz.png", plane=("x", "z"), unit="km")
    (ax,) = drawn[0].axes
    lines = ax.get_lines()
    assert len(lines) == 3  # the track, its start, its end; nothing for the empty one
    np.testing.assert_array_equal(lines[0].get_xdata(), [0, 10, 20])
    np.testing.assert_array_equal(lines[0].get_ydata(), [0, 1, 3])
    assert (lines[1].get_xdata(), lines[1].get_ydata()) == (0, 0)
    assert (lines[2].get_xdata(), lines[2].get_ydata()) == (20, 3)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [km]", "z [km]")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["a"]
