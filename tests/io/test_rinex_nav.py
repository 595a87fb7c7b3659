"""Navigation reader: every ephemeris parameter equals georinex's (test-only) on the shared
files; RINEX 2 GLONASS records read like their RINEX 3 twins."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.rinex_text import as_rinex4, with_glonass_status_lines
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.model.gpstime import BDT_MINUS_GPST_S

KEPLER_NAMES = {
    "af0": "SVclockBias",
    "af1": "SVclockDrift",
    "af2": "SVclockDriftRate",
    "crs": "Crs",
    "delta_n": "DeltaN",
    "m0": "M0",
    "cuc": "Cuc",
    "e": "Eccentricity",
    "cus": "Cus",
    "sqrt_a": "sqrtA",
    "toe_sow": "Toe",
    "cic": "Cic",
    "omega0": "Omega0",
    "cis": "Cis",
    "i0": "Io",
    "crc": "Crc",
    "omega": "omega",
    "omega_dot": "OmegaDot",
    "idot": "IDOT",
}
GLONASS_NAMES = {"minus_tau_n": "SVclockBias", "gamma_n": "SVrelFreqBias"}
GLONASS_M = {"x": "X", "vx": "dX", "ax": "dX2", "y": "Y", "vy": "dY", "z": "Z", "vz": "dZ"}
FILES = ("septentrio_static/base.nav", "yamatogawa_ublox_walk/brdc0060.10n")
GPS_EPOCH = np.datetime64("1980-01-06T00:00:00", "ns")


@pytest.fixture(scope="module", params=FILES)
def both(request):
    georinex = pytest.importorskip("georinex")
    path = require_shared(request.param)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = georinex.load(path)
    return read_nav(path), reference


def _matches(reference, sat, toc_calendar, expected: dict[str, float], rtol: float) -> bool:
    """True when one georinex entry of this satellite and epoch has all expected values."""
    when = GPS_EPOCH + np.timedelta64(round(float(toc_calendar) * 1e9), "ns")
    if when not in reference.time.values:
        return False
    at = reference.sel(time=when)
    for sv in (str(s) for s in reference.sv.values if str(s).startswith(sat)):
        values = [float(at[name].sel(sv=sv)) for name in expected]
        if np.allclose(values, list(expected.values()), rtol=rtol, atol=0.0):
            return True
    return False


@pytest.mark.slow
def test_kepler_parameters_equal_georinex(both):
    nav, reference = both
    k = nav.kepler
    assert len(k) > 10
    for i in range(len(k)):
        sat = f"{k.system[i]}{k.prn[i]:02d}"
        toc = k.toc[i] + (BDT_MINUS_GPST_S if k.system[i] == "C" else 0.0)
        expected = {name: float(k[ours][i]) for ours, name in KEPLER_NAMES.items()}
        assert _matches(reference, sat, toc, expected, rtol=0.0), (sat, k.line[i])


@pytest.mark.slow
def test_glonass_parameters_equal_georinex(both):
    nav, reference = both
    g = nav.glonass
    for i in range(len(g)):
        sat = f"R{g.prn[i]:02d}"
        toc = g.toc[i] - nav.leap_seconds
        expected = {name: float(g[ours][i]) for ours, name in GLONASS_NAMES.items()}
        expected |= {name: float(g[ours][i]) for ours, name in GLONASS_M.items()}  # georinex: m
        assert _matches(reference, sat, toc, expected, rtol=1e-14), (sat, g.line[i])


def _rinex2_glonass(rinex3_text: str) -> str:
    """The GLONASS records of a RINEX 3 navigation file, written as a RINEX 2.11 'G' file."""
    lines = rinex3_text.splitlines()
    start = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    out = [
        f"{'     2.11           G: GLONASS NAV DATA':<60}RINEX VERSION / TYPE",
        f"{'    18':<60}LEAP SECONDS",
        f"{'':<60}END OF HEADER",
    ]
    for i in range(start, len(lines)):
        line = lines[i]
        if line.startswith("R"):
            y, mo, d, h, mi, s = (int(p) for p in line[4:23].split())
            out.append(f"{int(line[1:3]):2d} {y % 100:02d} {mo:2d} {d:2d} {h:2d} {mi:2d}{s:5.1f}")
            out[-1] += line[23:80]
            out.extend("   " + lines[i + k][4:80] for k in (1, 2, 3))
    return "\n".join(out) + "\n"


def test_rinex2_glonass_file(tmp_path):
    source = require_shared("septentrio_static/base.nav")
    path = tmp_path / "glonass.24g"
    path.write_text(_rinex2_glonass(source.read_text()))
    v2, v3 = read_nav(path), read_nav(source)
    assert v2.problems == ()
    assert len(v2.glonass) == len(v3.glonass) > 0
    assert len(v2.kepler) == 0
    np.testing.assert_array_equal(v2.glonass.toc, v3.glonass.toc)
    for name, values in v3.glonass.params.items():
        np.testing.assert_array_equal(v2.glonass[name], values, err_msg=name)


def _params_equal(a, b) -> None:
    assert len(a) == len(b)
    np.testing.assert_array_equal(a.prn, b.prn)
    np.testing.assert_array_equal(a.toc, b.toc)
    for name in a.params:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def test_rinex4_is_read_by_record_type(tmp_path):
    """The same records behind '> EPH' lines read as in RINEX 3; CNAV, STO, ION counted."""
    source = require_shared("septentrio_static/base.nav")
    path = tmp_path / "base.rnx"
    path.write_bytes(as_rinex4(source.read_bytes()))
    nav, v3 = read_nav(path), read_nav(source)
    assert nav.problems == ()
    assert nav.skipped == {"EPH CNAV": 1, "STO LNAV": 1, "ION LNAV": 1}
    _params_equal(nav.kepler, v3.kepler)
    _params_equal(nav.glonass, v3.glonass)


def test_rinex4_record_without_its_type_line_is_skipped(tmp_path):
    source = require_shared("septentrio_static/base.nav")
    text = as_rinex4(source.read_bytes()).replace(b"> EPH G06 LNAV\n", b"", 1)
    path = tmp_path / "base.rnx"
    path.write_bytes(text)
    nav = read_nav(path)
    line = text.split(b"\n").index(next(x for x in text.split(b"\n") if x.startswith(b"G06"))) + 1
    assert nav.problems == (f"{path}:{line}: record without its '> EPH' line: skipped",)
    assert len(nav.kepler) == len(read_nav(source).kepler) - 1


def test_rinex305_glonass_fifth_line_is_read(tmp_path):
    source = require_shared("septentrio_static/base.nav")
    status = b"     1.500000000000E+01 2.793967723846E-09 3.000000000000E+00 0.000000000000E+00"
    path = tmp_path / "base305.nav"
    path.write_bytes(with_glonass_status_lines(source.read_bytes(), status))
    nav, v304 = read_nav(path), read_nav(source)
    assert nav.problems == ()
    assert len(nav.glonass) == len(v304.glonass) > 0
    np.testing.assert_array_equal(nav.glonass["status_flags"], 15.0)
    np.testing.assert_array_equal(nav.glonass["delta_tau_n"], 2.793967723846e-09)
    np.testing.assert_array_equal(nav.glonass["urai"], 3.0)
    np.testing.assert_array_equal(nav.glonass["health_flags"], 0.0)
    assert np.isnan(v304.glonass["status_flags"]).all()
    for name in ("x", "vx", "ax", "minus_tau_n", "channel"):
        np.testing.assert_array_equal(nav.glonass[name], v304.glonass[name])
    _params_equal(nav.kepler, v304.kepler)
