"""The GNSS velocity pipeline's reporting."""

from __future__ import annotations

import logging

import pytest

from tests.conftest import require_shared
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs


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
