"""The GNSS velocity pipeline's reporting."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.gnss.test_phase_rate import _obs
from vo_doppler.errors import InputError
from vo_doppler.gnss.pipeline import check_elevation_mask, gnss_position, gnss_velocity
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs


@pytest.mark.slow
@pytest.mark.shared_data
def test_a_satellite_without_ephemeris_is_warned_once(caplog):
    """Septentrio's R02 has no healthy ephemeris: the rows are computed twice (SPP fixes, then
    the smoothed track) and the warning came twice (QA report, finding 18)."""
    obs = read_obs(require_shared("septentrio_static/rover.obs"))
    nav = read_nav(require_shared("septentrio_static/base.nav"))
    with caplog.at_level(logging.WARNING):
        result = gnss_velocity(obs, nav, "R")
    warned = [r.getMessage() for r in caplog.records if "no healthy ephemeris" in r.getMessage()]
    assert warned == [
        "satellite R02: no healthy ephemeris from GPS time 1403252400.0 (602 rows) skipped"
    ]
    assert result.rows.missing == (
        "R02: no healthy ephemeris from GPS time 1403252400.0 (602 rows)",
    )


T = 1.0e9 + np.arange(3.0)
OBS = _obs(np.zeros(3), np.zeros(3), np.full(3, -1), T)
"""Three epochs of one GPS satellite with an L1 Doppler: enough for the argument checks, which
come before any solution (no navigation data is needed for them to fail)."""


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"elevation_mask_rad": 10.0}, r"elevation_mask_rad = 10: .*looks like degrees"),
        ({"elevation_mask_rad": -0.1}, r"elevation_mask_rad = -0.1: .*\[0, π/2\) rad$"),
        ({"elevation_mask_rad": float("nan")}, "elevation_mask_rad = nan"),
        ({"bands": "x"}, "bands: expected RINEX band digits 1-9"),
        ({"bands": "5"}, r"bands = '5': the file has no Doppler .* \(it has bands 1\)"),
        (
            {"range_rate": "bogus"},
            "^range_rate: unknown range rate source 'bogus'; choose from doppler, phase$",
        ),
        ({"receiver_ecef": np.zeros(3)}, "receiver_ecef is .*, 0 m from the Earth's centre"),
        ({"receiver_ecef": np.full(3, np.nan)}, "receiver_ecef is .*, nan m from"),
        ({"receiver_ecef": np.ones((2, 3)) * 4e6}, r"receiver_ecef has shape \(2, 3\)"),
        (
            {"receiver_ecef": np.array([[6.4e6, 0, 0], [6.4e6, 0, 0], [0, 0, 0]])},
            "receiver_ecef at epoch 2 is",
        ),
    ],
)
def test_arguments_out_of_their_domain_are_input_errors_naming_them(arguments, message):
    """Each of these gave a solution valid at no epoch, without a word (QA round 3, finding
    3), or a bare ValueError."""
    with pytest.raises(InputError, match=message):
        gnss_velocity(OBS, None, "G", **arguments)


@pytest.mark.parametrize("solve", [gnss_velocity, gnss_position])
def test_systems_other_than_rinex_letters_are_refused_naming_the_letter(solve):
    with pytest.raises(InputError, match=r"^systems = 'Gx': unknown satellite system 'x'; choose"):
        solve(OBS, None, "Gx")


@pytest.mark.parametrize("value", [0.0, np.radians(10.0), np.nextafter(np.pi / 2, 0)])
def test_an_elevation_mask_in_range_is_accepted(value):
    assert check_elevation_mask(value) == value
