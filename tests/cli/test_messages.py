"""Error messages name the likely cause and the option that fixes it, in plain numbers."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import REPO_ROOT
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"


def test_swapped_rinex_files_say_what_they_look_like(tmp_path):
    with pytest.raises(InputError, match=r"looks like a navigation file .*swapped"):
        read_obs(SAMPLE / "gnss" / "brdc.nav")
    with pytest.raises(InputError, match=r"looks like an observation file .*swapped"):
        read_nav([Path(SAMPLE / "gnss" / "rover.obs")])
