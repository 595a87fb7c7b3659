"""Image folders and their timestamps."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.io.images import list_images, read_image, read_times, times_from_fps


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.001, 100.0), min_size=1, max_size=30), st.booleans())
def test_times_round_trip(tmp_path_factory, steps, as_csv):
    times = np.cumsum(steps) + 1000.0
    path = tmp_path_factory.mktemp("t") / ("times.csv" if as_csv else "times.txt")
    if as_csv:
        path.write_text("frame,t\n" + "".join(f"{i},{float(t)!r}\n" for i, t in enumerate(times)))
    else:
        path.write_text("".join(f"{float(t)!r}\n" for t in times))
    np.testing.assert_array_equal(read_times(path, len(times)), times)


def test_non_monotonic_times_name_the_line(tmp_path):
    path = tmp_path / "times.txt"
    path.write_text("0.0\n0.1\n0.1\n0.3\n")
    with pytest.raises(InputError, match=r"times.txt:3: timestamps must increase"):
        read_times(path, 4)
    path.write_text("0.0\nabc\n")
    with pytest.raises(InputError, match=r"times.txt:2: timestamp is not a number"):
        read_times(path, 2)


def test_fps_times():
    np.testing.assert_allclose(times_from_fps(10.0, 3), [0.0, 0.1, 0.2])
    with pytest.raises(InputError, match="positive"):
        times_from_fps(0.0, 3)


def test_folder_listing_and_unreadable_images(tmp_path):
    for name in ("b.png", "a.png"):
        cv2.imwrite(str(tmp_path / name), np.full((8, 8), 100, np.uint8))
    (tmp_path / "c.jpg").write_bytes(b"not a jpeg")
    (tmp_path / "notes.txt").write_text("ignored")
    files = list_images(tmp_path)
    assert [f.name for f in files] == ["a.png", "b.png", "c.jpg"]
    assert read_image(files[0]).shape == (8, 8)
    assert read_image(files[2]) is None
