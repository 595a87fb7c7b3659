"""The GPS-fix CSV reader on fixes outside the Earth's coordinates."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.gps_fixes import read_gps_fixes


def test_fixes_with_lat_and_lon_swapped_are_an_error_suggesting_the_swap(tmp_path):
    """Every fix out of range (lat -122°): an error naming the file, not an empty track that
    failed later in the dead reckoning with exit 3."""
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg\n" + "".join(f"{k},-122.4,37.7\n" for k in range(5)))
    with pytest.raises(InputError, match=r"gps.csv: all 5 fixes .* columns swapped\?"):
        read_gps_fixes(path)


def test_some_fixes_out_of_range_are_skipped_and_counted(tmp_path):
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg\n0,37.7,-122.4\n1,-122.4,37.7\n2,37.8,-122.4\n")
    fixes = read_gps_fixes(path)
    np.testing.assert_allclose(fixes.t, [0.0, 2.0])
    assert fixes.n_skipped == 1
