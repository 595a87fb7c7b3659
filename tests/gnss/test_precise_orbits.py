"""Satellite states from precise orbits: exact on a polynomial orbit, at the interpolation
error of a Keplerian one, against RTKLIB's peph2pos on the real IAC product, and the edges
(no extrapolation, missing nodes, unknown satellites, attached clock file)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import OMEGA_E, rotate_earth
from vo_doppler.gnss.precise_orbits import precise_states
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.model.precise_orbits import PreciseOrbits, SatelliteClocks

T0 = 1_217_253_600.0
NODES = T0 + 900.0 * np.arange(20)
MU = 3.986005e14


def _to_ecef(position_i, velocity_i, t):
    """Quasi-inertial → ECEF at GPS time t (rotation angle ω_e (t − T0))."""
    position = rotate_earth(position_i, t - T0)
    velocity = rotate_earth(velocity_i, t - T0) - OMEGA_E["G"] * np.stack(
        [-position[:, 1], position[:, 0], np.zeros(len(position))], axis=1
    )
    return position, velocity


def _polynomial(t):
    """A degree-9 inertial trajectory, its velocity and acceleration (x = (t − T0)/3600)."""
    x = (t - T0) / 3600.0
    rng = np.random.default_rng(7)
    coefficients = rng.normal(0.0, 2e6, (10, 3)) / 5.0 ** np.arange(10)[:, None]
    coefficients[0] = [1.5e7, -1.8e7, 1.2e7]
    powers = np.arange(10)
    value = (x[:, None] ** powers) @ coefficients
    first = (powers[1:] * x[:, None] ** (powers[1:] - 1)) @ coefficients[1:] / 3600.0
    second = (
        (powers[2:] * (powers[2:] - 1) * x[:, None] ** (powers[2:] - 2)) @ coefficients[2:]
    ) / 3600.0**2
    return value, first, second


def _orbits(position_i, clock):
    return PreciseOrbits(
        NODES, np.array(["G07"]), rotate_earth(position_i, NODES - T0)[:, None, :], clock
    )


def test_polynomial_orbit_is_exact():
    position_i, _, _ = _polynomial(NODES)
    clock = (1e-4 + 2e-11 * (NODES - T0))[:, None]
    states = precise_states(
        _orbits(position_i, clock), "G", 7, t := T0 + np.linspace(0, 17100, 301)
    )
    r, v, a = _polynomial(t)
    position, velocity = _to_ecef(r, v, t)
    assert states.valid.all()
    np.testing.assert_allclose(states.position, position, atol=1e-5, rtol=0)
    np.testing.assert_allclose(states.velocity, velocity, atol=1e-8, rtol=0)
    relativity = -2.0 * np.einsum("ni,ni->n", r, v) / SPEED_OF_LIGHT**2
    relativity_rate = (
        -2.0 * (np.einsum("ni,ni->n", v, v) + np.einsum("ni,ni->n", r, a)) / SPEED_OF_LIGHT**2
    )
    np.testing.assert_allclose(
        states.clock_bias_s, 1e-4 + 2e-11 * (t - T0) + relativity, atol=1e-17, rtol=0
    )
    np.testing.assert_allclose(states.clock_drift, 2e-11 + relativity_rate, atol=1e-20, rtol=0)


def _kepler(t, a=26_560e3, e=0.01, inc=0.96, raan=0.5, argp=0.3, m0=0.1):
    """Two-body orbit in the inertial frame: position and velocity (Keplerian elements)."""
    n = np.sqrt(MU / a**3)
    mean = m0 + n * (t - T0)
    ecc = mean.copy()
    for _ in range(50):
        ecc -= (ecc - e * np.sin(ecc) - mean) / (1.0 - e * np.cos(ecc))
    rate = n / (1.0 - e * np.cos(ecc))
    beta = np.sqrt(1.0 - e * e)
    plane = np.stack([a * (np.cos(ecc) - e), a * beta * np.sin(ecc)], axis=1)
    plane_rate = np.stack([-a * np.sin(ecc) * rate, a * beta * np.cos(ecc) * rate], axis=1)
    co, so, ci, si, cw, sw = (f(v) for v in (raan, inc, argp) for f in (np.cos, np.sin))
    p = np.array([co * cw - so * sw * ci, so * cw + co * sw * ci, sw * si])
    q = np.array([-co * sw - so * cw * ci, -so * sw + co * cw * ci, cw * si])
    basis = np.stack([p, q])
    return plane @ basis, plane_rate @ basis


@pytest.mark.parametrize(
    ("n_points", "position_tol", "velocity_tol"), [(10, 1e-4, 1e-6), (12, 3e-6, 3e-8)]
)
def test_keplerian_orbit_within_interpolation_error(n_points, position_tol, velocity_tol):
    """A GPS-like orbit tabulated every 15 min: the degree-9 default is 0.06 mm / 0.2 µm/s
    away from the two-body truth (degree 11: 1.4 µm / 6 nm/s), far below SP3's 1 mm digit."""
    position_i, _ = _kepler(NODES)
    orbits = _orbits(position_i, np.zeros((NODES.size, 1)))
    t = T0 + np.linspace(900.0 * 4, 900.0 * 15, 1001)
    states = precise_states(orbits, "G", 7, t, n_points=n_points)
    position, velocity = _to_ecef(*_kepler(t), t)
    assert np.abs(states.position - position).max() < position_tol
    assert np.abs(states.velocity - velocity).max() < velocity_tol


def test_relativistic_rate_is_the_derivative_of_the_relativistic_term():
    position_i, _ = _kepler(NODES, e=0.05)
    orbits = _orbits(position_i, np.zeros((NODES.size, 1)))
    t = T0 + 7000.0 + np.array([-0.5, 0.0, 0.5])
    states = precise_states(orbits, "G", 7, t)
    numeric = (states.clock_bias_s[2] - states.clock_bias_s[0]) / 1.0
    assert states.clock_drift[1] == pytest.approx(numeric, abs=1e-16)
    assert abs(states.clock_drift[1]) > 1e-12  # the term is really there (e = 0.05)


def test_edges_are_invalid_not_extrapolated():
    position_i, _ = _kepler(NODES)
    position_e = rotate_earth(position_i, NODES - T0)
    table = np.stack([position_e, position_e], axis=1)
    table[10, 1] = np.nan  # one missing epoch: the window shifts around it
    table[14:16, 1] = np.nan  # two: a query next to them is invalid
    orbits = PreciseOrbits(NODES, np.array(["G07", "E11"]), table, np.zeros((20, 2)))
    t = np.array([T0 - 1.0, T0, NODES[-1], NODES[-1] + 1.0, T0 + 9100.0, T0 + 5000.0])
    system = np.array(["G", "G", "G", "G", "E", "R"])
    prn = np.array([7, 7, 7, 7, 11, 7])
    states = precise_states(orbits, system, prn, t)
    np.testing.assert_array_equal(states.valid, [False, True, True, False, True, False])
    np.testing.assert_array_equal(states.record, [-1, 0, 0, -1, 1, -1])
    np.testing.assert_allclose(states.position[1], position_e[0], atol=1e-6)
    np.testing.assert_allclose(states.position[2], position_e[-1], atol=1e-6)
    reference = precise_states(orbits, "G", 7, T0 + 9100.0)
    np.testing.assert_allclose(states.position[4], reference.position[0], atol=1e-3)
    during_gap = precise_states(orbits, "E", 11, T0 + 13000.0)
    assert not during_gap.valid[0] and np.isnan(during_gap.position).all()


def test_attached_clock_file_replaces_the_sp3_clock():
    position_i, _ = _kepler(NODES, e=0.0)
    orbits = _orbits(position_i, np.full((NODES.size, 1), 5e-4))
    t_clock = T0 + 30.0 * np.arange(400)
    clocks = SatelliteClocks(
        t_clock, np.array(["G07"]), (1e-5 + 3e-12 * (t_clock - T0) ** 1.5)[:, None]
    )
    t = T0 + 1000.0 + np.array([0.0, 15.0])
    states = precise_states(orbits.with_clocks(clocks), "G", 7, t)
    slope = 3e-12 * (1020.0**1.5 - 990.0**1.5) / 30.0
    start = 1e-5 + 3e-12 * 990.0**1.5
    # circular orbit: the relativistic terms vanish up to the polynomial's tiny error
    np.testing.assert_allclose(states.clock_bias_s, start + slope * (t - T0 - 990.0), atol=1e-15)
    np.testing.assert_allclose(states.clock_drift, slope, atol=1e-16)


RTKLIB_SYSTEMS = {"G": "SYS_GPS", "R": "SYS_GLO", "E": "SYS_GAL", "C": "SYS_CMP", "J": "SYS_QZS"}


def test_real_product_against_rtklib():
    """RTKLIB reads the same file itself (readsp3) and interpolates (peph2pos: degree-10
    Neville in a rotated frame; velocity by a 1 ms finite difference, clock linear, with the
    relativistic bias but no relativistic rate, so the drift is checked against the slope of
    its clock bias over ±0.5 s). Checked at the comma2k19 minute."""
    rtk = pytest.importorskip("pyrtklib")
    path = require_shared("comma2k19_example1/Sta20124_1400_1845.sp3")
    orbits = read_sp3(path)
    nav = rtk.nav_t()
    rtk.readsp3(str(path), nav, 0)
    checked = 0
    for sow in (404106.0, 404136.3, 404166.0):
        t = 2012 * 604800.0 + sow
        for sat in orbits.sat_id:
            prn = int(sat[1:])
            number = rtk.satno(
                getattr(rtk, RTKLIB_SYSTEMS[sat[0]]), prn + (192 if sat[0] == "J" else 0)
            )
            theirs, bias, ok = _rtklib(rtk, nav, number, sow)
            drift = (
                _rtklib(rtk, nav, number, sow + 0.5)[1] - _rtklib(rtk, nav, number, sow - 0.5)[1]
            )
            ours = precise_states(orbits, sat[0], prn, t)
            if not ok or not np.isfinite(theirs[:3]).all() or not ours.valid[0]:
                continue
            np.testing.assert_allclose(ours.position[0], theirs[:3], atol=1e-3)
            np.testing.assert_allclose(ours.velocity[0], theirs[3:], atol=1e-3)
            assert ours.clock_bias_s[0] * SPEED_OF_LIGHT == pytest.approx(
                bias * SPEED_OF_LIGHT, abs=1e-3
            )
            assert ours.clock_drift[0] * SPEED_OF_LIGHT == pytest.approx(
                drift * SPEED_OF_LIGHT, abs=1e-4
            )
            checked += 1
    assert checked > 150


def _rtklib(rtk, nav, number, sow):
    rs, dts, var = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(2), rtk.Arr1Ddouble(1)
    ok = rtk.peph2pos(rtk.gpst2time(2012, sow), number, nav, 1, rs, dts, var)
    return np.array([rs[i] for i in range(6)]), dts[0], ok
