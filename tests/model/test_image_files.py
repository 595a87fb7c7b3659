"""ImageFiles: a recording's image paths held as one folder and the names (issue 30)."""

import pickle
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.model.image_files import ImageFiles

NAMES = st.text(alphabet="ab0.-_ é", min_size=1, max_size=6).filter(lambda n: n not in {".", ".."})
FOLDERS = st.sampled_from(["/data/run/image_0", "rel/images", ".", "/"])


@given(FOLDERS, st.lists(NAMES, max_size=8))
def test_paths_of_one_folder_come_back_as_given(folder, names):
    paths = [Path(folder) / name for name in names]
    files = ImageFiles.of(paths)
    assert list(files) == paths
    assert [files[k] for k in range(len(paths))] == paths
    assert len(files) == len(paths)
    if paths:
        assert files[-1] == paths[-1]
        assert files.names == tuple(p.name for p in paths)


@given(st.lists(st.tuples(FOLDERS, NAMES), max_size=8))
def test_paths_of_several_folders_come_back_as_given(pairs):
    paths = [Path(folder) / name for folder, name in pairs]
    files = ImageFiles.of(paths)
    assert list(files) == paths
    assert files == paths and files == tuple(paths) and files == ImageFiles.of(paths)


@given(st.lists(NAMES, max_size=8), st.integers(-9, 9), st.integers(-9, 9), st.integers(1, 3))
def test_a_slice_is_the_slice_of_the_paths(names, start, stop, step):
    paths = [Path("/d") / name for name in names]
    part = ImageFiles.of(paths)[start:stop:step]
    assert isinstance(part, ImageFiles)
    assert list(part) == paths[start:stop:step]


def test_select_keeps_the_flagged_files_and_needs_one_flag_each():
    files = ImageFiles.in_folder("/d", ["0.png", "1.png", "2.png"])
    assert list(files.select([True, False, True])) == [Path("/d/0.png"), Path("/d/2.png")]
    with pytest.raises(ValueError):
        files.select([True, False])


def test_equality_pickling_and_an_index_out_of_range():
    files = ImageFiles.in_folder("/d", ["0.png", "1.png"])
    assert files == [Path("/d/0.png"), "/d/1.png"]
    assert files != [Path("/d/0.png")]
    assert files != ImageFiles.in_folder("/e", ["0.png", "1.png"])
    assert (files == 3) is False
    assert pickle.loads(pickle.dumps(files)) == files
    assert ImageFiles.of(files) is files
    assert "2 files" in repr(files)
    with pytest.raises(IndexError):
        files[2]
    with pytest.raises(TypeError):
        hash(files)


def test_thirty_minutes_of_names_take_far_less_than_paths():
    """27,000 frames (30 min at 15 Hz): the names and the folder, not one Path each."""
    names = [f"{k:06d}.png" for k in range(27_000)]
    files = ImageFiles.in_folder("/data/drive/image_0", names)
    held = sys.getsizeof(files.names) + sum(sys.getsizeof(n) for n in files.names)
    assert held < 2.0 * 2**20
    assert str(files[12_345]) == "/data/drive/image_0/012345.png"
