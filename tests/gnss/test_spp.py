"""Atmosphere models against RTKLIB (pyrtklib, test-only); SPP on the static Septentrio file."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tests.conftest import require_shared
from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from tests.helpers.time_shift import WEEKS_NEAR_1E9_S
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.gnss.atmosphere import klobuchar_delay, troposphere_delay
from vo_doppler.gnss.spp import nearest_time, receiver_positions, solve_spp
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.timeseries import TIME_TOLERANCE_S

KLOBUCHAR = np.array([1.8626e-08, 2.2352e-08, -1.1921e-07, -5.9605e-08])
KLOBUCHAR = np.concatenate([KLOBUCHAR, [1.2902e05, 1.6384e05, -1.9661e05, -2.6214e05]])


def _array(rtk, values):
    out = rtk.Arr1Ddouble(len(values))
    for i, v in enumerate(values):
        out[i] = float(v)
    return out


@pytest.mark.parametrize("t", [1403252400.0, 1403252400.0 + 5 * 3600, 1403252400.0 + 14 * 3600])
@pytest.mark.parametrize("lat_deg", [35.13, -60.0, 5.0])
def test_klobuchar_and_saastamoinen_match_rtklib(t, lat_deg):
    rtk = pytest.importorskip("pyrtklib")
    lat, lon, height = np.deg2rad(lat_deg), np.deg2rad(136.98), 104.9
    week = int(t // 604800)
    time = rtk.gpst2time(week, t - week * 604800)
    for elevation_deg, azimuth_deg in [(10.0, 30.0), (45.0, 200.0), (85.0, 300.0)]:
        el, az = np.deg2rad(elevation_deg), np.deg2rad(azimuth_deg)
        pos = _array(rtk, [lat, lon, height])
        azel = _array(rtk, [az, el])
        iono = rtk.ionmodel(time, _array(rtk, KLOBUCHAR), pos, azel)
        ours = klobuchar_delay(KLOBUCHAR, lat, lon, np.array([el]), np.array([az]), t)[0]
        assert ours == pytest.approx(iono, abs=1e-6)
        tropo = rtk.tropmodel(time, pos, azel, 0.7)
        assert troposphere_delay(lat, height, np.array([el]))[0] == pytest.approx(tropo, abs=1e-6)


@pytest.mark.shared_data
@pytest.mark.parametrize("systems", ["GREC", "G"])
def test_static_septentrio_spp(systems):
    obs = read_obs(require_shared("septentrio_static/rover.obs"))
    nav = read_nav(require_shared("septentrio_static/base.nav"))
    lat, lon, height = np.loadtxt(require_shared("septentrio_static/rover_position.txt"))
    truth = geodetic_to_ecef(np.deg2rad(lat), np.deg2rad(lon), height)
    solution = solve_spp(obs, nav, systems)
    assert solution.valid.all()
    enu = EnuFrame.from_ecef(truth).ecef_to_enu(solution.position_ecef)
    assert np.median(np.linalg.norm(enu[:, :2], axis=1)) < 5.0
    assert np.median(np.abs(enu[:, 2])) < 5.0
    assert np.all(np.std(enu, axis=0) < 1.0)


@pytest.mark.slow
@pytest.mark.shared_data
def test_spp_without_redundancy_is_solved_but_not_valid():
    """Four GPS satellites: the position is computed (no redundancy, nothing to test) and not
    valid; with every satellite valid and verified agree."""
    obs = read_obs(require_shared("septentrio_static/rover.obs"))
    nav = read_nav(require_shared("septentrio_static/base.nav"))
    four = (obs.system == "G") & np.isin(obs.prn, [5, 13, 15, 20])  # above the mask throughout
    solution = solve_spp(obs.subset(four), nav, "G")
    solved = np.isfinite(solution.position_ecef[:, 0])
    assert solved.mean() > 0.9
    assert not solution.valid.any() and not solution.verified.any()
    everything = solve_spp(obs, nav, "G")
    np.testing.assert_array_equal(everything.valid, everything.verified)
    assert everything.valid.all()


# Times on a coarse grid (ties and repeated epochs are common) and a validity mask.
epochs = st.lists(st.tuples(st.integers(0, 40), st.booleans()), min_size=1, max_size=60)


@given(epochs)
def test_nearest_valid_fix_is_the_pairwise_argmin(rows):
    """The nearest valid epoch by binary search is the one the full (epochs × valid) table
    picks: the smallest distance, ties (within TIME_TOLERANCE_S) to the earlier and to the
    first of equal times."""
    t = np.sort(np.array([step for step, _ in rows], dtype=float) * 0.05)
    valid = np.array([flag for _, flag in rows])
    position = np.column_stack([np.arange(t.size, dtype=float), t, -t])
    position[~valid] = np.nan
    solution = SppSolution(t, position, {}, np.zeros(t.size), t, t, valid, 0)
    out = receiver_positions(solution, None)
    if not valid.any():
        assert np.isnan(out).all()
        return
    good = np.flatnonzero(valid)
    distance = np.abs(t[:, None] - t[good][None, :])
    nearest = distance <= distance.min(axis=1, keepdims=True) + TIME_TOLERANCE_S
    expected = good[nearest.argmax(axis=1)]  # within the tolerance of a tie: the earlier
    assert np.array_equal(out, position[np.where(valid, np.arange(t.size), expected)])
    assert np.array_equal(nearest_time(t[good], t), np.searchsorted(good, expected))


def test_nearest_time_on_a_long_record_keeps_memory_linear():
    """A day at 20 Hz with every other epoch valid: the pairwise table would take 12 TB; the
    search holds a few arrays of the record's length. Odd epochs lie halfway: the earlier."""
    t = np.arange(1_728_000, dtype=float)
    tracemalloc.start()
    try:
        index = nearest_time(t[::2], t)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert np.array_equal(index, np.arange(t.size) // 2)
    assert peak < 10 * t.nbytes


def test_systems_absent_from_the_file_are_an_input_error_naming_those_it_has(tmp_path):
    """GPS pseudoranges and a GLONASS Doppler only: asking for Galileo names G (the one system
    with pseudoranges) before any satellite state is needed."""
    text = rinex3_header({"G": ["C1C", "D1C"], "R": ["D1C"]}) + rinex3_epoch(
        "2024 06 24 08 20  0.0000000",
        [("G05", [field(2.1e7), field(-500.0)]), ("R07", [field(300.0)])],
    )
    path = tmp_path / "gps_only.obs"
    path.write_text(text)
    obs = read_obs(path)
    with pytest.raises(InputError, match=r"no pseudoranges of the systems 'E'; .* of G \(e\.g\."):
        solve_spp(obs, None, "E")
    with pytest.raises(InputError, match=r"gps_only\.obs"):
        solve_spp(obs, None, "RE")


@pytest.mark.parametrize("origin", [0.0, 1425953400.0, 1425953400.0 + WEEKS_NEAR_1E9_S])
def test_an_epoch_halfway_between_fixes_takes_the_earlier_at_any_time_origin(origin):
    """20-Hz epochs with every other one fixed: the odd ones lie halfway, and take the earlier
    fix at GPS seconds near 2.4e9 as at 0, where the rounding of the times made some nearer the
    later (42 m away on the sample; issue 30)."""
    steps = np.arange(400)
    t = origin + 0.05 * steps
    np.testing.assert_array_equal(nearest_time(t[::2], t), steps // 2)
