"""The smartLoc raw CSV reader: exact values on synthetic files, every refusal naming the line,
a property test over random rows, and the real Berlin file of ../shared/data."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import require_shared
from tests.helpers.smartloc_text import HEADER, Measurement, Truth, row, smartloc_text
from vo_doppler.bounds import DOPPLER
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.io.smartloc import read_smartloc
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

REAL = "smartloc_berlin/tu_chemnitz_berlin_1_raw.csv"
GPS_L1_WAVELENGTH = SPEED_OF_LIGHT / 1575.42e6


def _read(tmp_path, text: str):
    path = tmp_path / "drive_raw.csv"
    path.write_text(text, encoding="utf-8")
    return read_smartloc(path), path


def _doppler_rows(obs):
    rows = np.flatnonzero(np.array([c[0] for c in obs.codes])[obs.code] == "D")
    return rows, obs.satellites()[rows]


def test_doppler_becomes_a_range_rate_by_each_signals_wavelength(tmp_path):
    epoch = Truth(126641.5)
    recording, _ = _read(
        tmp_path,
        smartloc_text(
            [
                (
                    epoch,
                    [
                        Measurement("GPS", 12, 222.1658, 0.128, nlos="0"),
                        # freqId 9 → channel k = 2 → G1 = 1602 + 2 · 0.5625 MHz
                        Measurement("Glonass", 20, 2219.386, 1.024, freq_id=9, nlos="1"),
                        Measurement("SBAS", 120, -10.0, 0.5, nlos="#"),
                    ],
                )
            ]
        ),
    )
    obs = recording.observations
    rows, sats = _doppler_rows(obs)
    assert sats.tolist() == ["G12", "R20", "S20"]
    glonass_wavelength = SPEED_OF_LIGHT / (1602.0e6 + 2 * 0.5625e6)
    wavelength = np.array([GPS_L1_WAVELENGTH, glonass_wavelength, GPS_L1_WAVELENGTH])
    fields = obs.row_fields
    np.testing.assert_allclose(fields["wavelength_m"][rows], wavelength, rtol=1e-15)
    np.testing.assert_allclose(
        fields["range_rate_mps"][rows],
        -wavelength * np.array([222.1658, 2219.386, -10.0]),
        rtol=1e-15,
    )
    np.testing.assert_allclose(
        fields["range_rate_sigma_mps"][rows], wavelength * [0.128, 1.024, 0.5], rtol=1e-15
    )
    np.testing.assert_array_equal(fields["sigma"][rows], [0.128, 1.024, 0.5])
    assert fields["nlos"][rows].tolist() == [0, 1, -1]
    assert recording.glonass_channels == {20: 2}
    assert obs.header.glonass_channels == {20: 2}
    assert recording.n_rows == 3
    assert obs.epoch_time.tolist() == [1900 * SECONDS_PER_WEEK + 126641.5]


def test_every_observation_row_carries_its_measurements_nlos_label_and_sigma(tmp_path):
    recording, _ = _read(
        tmp_path,
        smartloc_text([(Truth(10.0), [Measurement(sv=5, nlos="1"), Measurement(sv=7)])]),
    )
    obs = recording.observations
    sats = obs.satellites()
    assert sorted(obs.codes) == ["C1C", "D1C", "L1C", "S1C"]
    assert obs.row_fields["nlos"][sats == "G05"].tolist() == [1, 1, 1, 1]
    assert obs.row_fields["nlos"][sats == "G07"].tolist() == [0, 0, 0, 0]
    codes = np.array(obs.codes)[obs.code]
    sigma = obs.row_fields["sigma"]
    assert sigma[(sats == "G05") & (codes == "C1C")].tolist() == [0.32]
    assert sigma[(sats == "G05") & (codes == "L1C")].tolist() == [0.004]
    assert np.isnan(sigma[codes == "S1C"]).all()
    assert np.isnan(obs.row_fields["range_rate_mps"][codes != "D1C"]).all()
    kept = obs.subset(sats == "G05")
    assert kept.row_fields["nlos"].tolist() == [1, 1, 1, 1]
    doppler = recording.doppler_sigma()
    assert doppler.sat_id.tolist() == ["G05", "G07"]
    np.testing.assert_allclose(doppler.sigma_mps, GPS_L1_WAVELENGTH * 0.128, rtol=1e-15)


def test_pseudorange_and_carrier_only_when_the_tracking_status_says_valid(tmp_path):
    recording, _ = _read(
        tmp_path,
        smartloc_text(
            [
                (
                    Truth(10.0),
                    [
                        Measurement(sv=1, tracking=1),  # pseudorange valid only
                        Measurement(sv=2, tracking=0),  # neither: Doppler and C/N0 only
                        Measurement(sv=3, tracking=3),
                    ],
                )
            ]
        ),
    )
    obs = recording.observations
    by_sat: dict[str, list[str]] = {}
    for sat, code in zip(obs.satellites(), obs.code, strict=True):
        by_sat.setdefault(str(sat), []).append(obs.codes[code])
    assert sorted(by_sat["G01"]) == ["C1C", "D1C", "S1C"]
    assert sorted(by_sat["G02"]) == ["D1C", "S1C"]
    assert sorted(by_sat["G03"]) == ["C1C", "D1C", "L1C", "S1C"]


def test_ground_truth_per_epoch(tmp_path):
    first, second = Truth(100.0, heading=-0.5, speed=3.0), Truth(100.2, speed=3.5)
    recording, _ = _read(
        tmp_path,
        smartloc_text([(first, [Measurement(sv=1), Measurement(sv=2)]), (second, [Measurement()])]),
    )
    truth = recording.truth
    assert len(truth) == 2
    np.testing.assert_allclose(truth.t, 1900 * SECONDS_PER_WEEK + np.array([100.0, 100.2]))
    assert truth.yaw_rad.tolist() == [-0.5, 1.25]
    assert truth.speed_mps.tolist() == [3.0, 3.5]
    assert truth.lat_rad[0] == math.radians(52.5)
    assert truth.line.tolist() == [2, 4]


def test_skipped_rows_are_counted_in_problems(tmp_path):
    recording, path = _read(
        tmp_path,
        smartloc_text(
            [
                (
                    Truth(10.0),
                    [
                        Measurement(gnss="IMES", sv=1),
                        Measurement(gnss="Glonass", sv=255, freq_id=7),
                        Measurement(sv=3, pseudorange_m=5.0),  # not a pseudorange
                        Measurement(sv=4),
                    ],
                )
            ]
        ),
    )
    assert recording.n_rows == 2
    assert len(recording.problems) == 3
    assert all(str(path) in p for p in recording.problems)
    assert any("IMES" in p and "line 2" in p for p in recording.problems)
    assert any("(prMes)" in p and "line 4" in p for p in recording.problems)
    sats = recording.observations.satellites()
    assert "C1C" not in [
        recording.observations.codes[c] for c in recording.observations.code[sats == "G03"]
    ]


@pytest.mark.parametrize(
    ("measurement", "message"),
    [
        (Measurement(extra={"Doppler measurement (doMes) [Hz]": "x"}), r":2: column \(doMes\)"),
        (Measurement(extra={"Doppler measurement (doMes) [Hz]": "inf"}), "not finite"),
        (Measurement(gnss="Beidou"), "unknown system 'Beidou'"),
        (Measurement(nlos="2"), "NLOS label '2'"),
        (Measurement(sv=40), "no GPS satellite 40"),
        (Measurement(gnss="Glonass", sv=3, freq_id=14), r"\(freqId\): 14"),
        (Measurement(doppler_sigma_hz=0.0), r"\(doStdev\): 0 SI outside 1e-09"),
        (Measurement(cn0=120.0), r"\(cno\): 120"),
        (Measurement(extra={"GPS week number (week) [weeks]": "4096"}), r"\(week\): 4096"),
        (Measurement(extra={"Latitude (GT Lat) [deg]": "91"}), r"\(GT Lat\): 91"),
        (Measurement(extra={"Velocity (GT Velocity) [m/s]": "400"}), r"\(GT Velocity\): 400"),
        (Measurement(extra={"Measurement time of week (rcvTow) [s]": "604800"}), "second of"),
        (Measurement(extra={"Tracking status (trkStat) []": "1.5"}), "not a whole number"),
    ],
)
def test_a_bad_value_is_an_error_naming_file_line_and_column(tmp_path, measurement, message):
    path = tmp_path / "bad_raw.csv"
    path.write_text(smartloc_text([(Truth(10.0), [measurement])]), encoding="utf-8")
    with pytest.raises(InputError, match=message) as caught:
        read_smartloc(path)
    assert str(caught.value).startswith(f"{path}:2: ")


def test_refusals_of_the_file_structure(tmp_path):
    cases = {
        "no header": ("", r":1: empty file"),
        "no column": (HEADER.replace("(doMes)", "(dopp)") + "\n", r"no column '\(doMes\)'"),
        "header only": (HEADER + "\n", "no measurement rows"),
        "short row": (HEADER + "\n1900;10.0;13\n", r":2: 3 fields, the header has 34"),
    }
    for name, (text, message) in cases.items():
        path = tmp_path / f"{name}.csv"
        path.write_text(text, encoding="utf-8")
        with pytest.raises(InputError, match=message):
            read_smartloc(path)


def test_an_epoch_whose_rows_disagree_on_the_ground_truth_is_refused(tmp_path):
    text = HEADER + "\n" + row(Truth(10.0), Measurement(sv=1)) + "\n"
    text += row(Truth(10.0, speed=9.0), Measurement(sv=2)) + "\n"
    with pytest.raises(InputError, match=r":3: ground truth \(GT Velocity\) differs from line 2"):
        _read(tmp_path, text)


def test_time_going_back_and_a_glonass_slot_changing_channel_are_refused(tmp_path):
    back = smartloc_text([(Truth(10.0), [Measurement()]), (Truth(9.0), [Measurement()])])
    with pytest.raises(InputError, match=r":3: measurement time .* goes back"):
        _read(tmp_path, back)
    slot = smartloc_text(
        [
            (Truth(10.0), [Measurement("Glonass", 4, freq_id=8)]),
            (Truth(11.0), [Measurement("Glonass", 4, freq_id=9)]),
        ]
    )
    with pytest.raises(InputError, match=r":3: GLONASS slot 4 on channel 2, but 1 on line 2"):
        _read(tmp_path, slot)


SYSTEM_NAMES = {"GPS": (1, 32), "Glonass": (1, 24), "SBAS": (120, 158), "Galileo": (1, 36)}


@st.composite
def measurements(draw):
    name = draw(st.sampled_from(sorted(SYSTEM_NAMES)))
    low, high = SYSTEM_NAMES[name]
    return Measurement(
        gnss=name,
        sv=draw(st.integers(low, high)),
        doppler_hz=draw(st.floats(DOPPLER.low, DOPPLER.high, allow_nan=False)),
        doppler_sigma_hz=draw(st.floats(1e-3, 1e3)),
        freq_id=draw(st.integers(0, 13)),
        nlos=draw(st.sampled_from(["0", "1", "#"])),
    )


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(epochs=st.lists(st.lists(measurements(), min_size=1, max_size=6), min_size=1, max_size=5))
def test_property_every_row_read_with_its_range_rate_sigma_and_label(tmp_path, epochs):
    """Random valid files: every row is read (one Doppler each, unless it repeats its epoch's
    satellite), with range rate −λ·D, σ λ·σ_D and its label, λ from the row's own system and
    GLONASS channel."""
    channels: dict[int, int] = {}
    for ms in epochs:
        for m in ms:
            if m.gnss == "Glonass":
                m.freq_id = channels.setdefault(m.sv, m.freq_id)
    text = smartloc_text([(Truth(10.0 + k), ms) for k, ms in enumerate(epochs)])
    recording, _ = _read(tmp_path, text)
    obs = recording.observations
    assert recording.n_rows == sum(len(ms) for ms in epochs)
    assert obs.epoch_time.size == len(epochs)
    rows, sats = _doppler_rows(obs)
    expected = {}
    for k, ms in enumerate(epochs):
        for m in ms:
            letter = {"GPS": "G", "Glonass": "R", "SBAS": "S", "Galileo": "E"}[m.gnss]
            prn = m.sv - 100 if letter == "S" else m.sv
            key = (k, f"{letter}{prn:02d}")
            frequency = 1602.0e6 + 0.5625e6 * (m.freq_id - 7) if letter == "R" else 1575.42e6
            expected.setdefault(key, (SPEED_OF_LIGHT / frequency, m))  # the first row is kept
    assert len(rows) == len(expected)
    epoch = np.searchsorted(obs.epoch_time, obs.time[rows])
    for r, k, sat in zip(rows, epoch, sats, strict=True):
        wavelength, m = expected[(int(k), str(sat))]
        assert obs.row_fields["range_rate_mps"][r] == pytest.approx(
            -wavelength * m.doppler_hz, rel=1e-14, abs=1e-12
        )
        assert obs.row_fields["range_rate_sigma_mps"][r] == pytest.approx(
            wavelength * m.doppler_sigma_hz, rel=1e-14
        )
        assert obs.row_fields["nlos"][r] == {"0": 0, "1": 1, "#": -1}[m.nlos]


def _real_rows(path):
    with path.open(encoding="utf-8", newline="") as handle:
        reader = csv.reader(handle, delimiter=";")
        header = next(reader)
        return header, list(reader)


@pytest.mark.shared_data
def test_the_berlin_file_every_row_with_range_rate_sigma_and_label():
    path = require_shared(REAL)
    header, rows = _real_rows(path)
    column = {name: next(k for k, h in enumerate(header) if name in h) for name in (
        "(doMes)", "(doStdev)", "(gnssId)", "(svId)", "(freqId)", "NLOS", "(rcvTow)",
    )}  # fmt: skip
    recording = read_smartloc(path)
    obs = recording.observations
    assert recording.n_rows == len(rows) == 545
    assert obs.epoch_time.size == len(recording.truth) == 31
    assert recording.problems == ()
    doppler, sats = _doppler_rows(obs)
    assert doppler.size == 545  # every row has its Doppler
    index = {
        (float(t), str(s)): r for t, s, r in zip(obs.time[doppler], sats, doppler, strict=True)
    }
    letters = {"GPS": "G", "Glonass": "R", "SBAS": "S"}
    for fields in rows:
        system = letters[fields[column["(gnssId)"]]]
        sv = int(fields[column["(svId)"]])
        sat = f"{system}{sv - 100 if system == 'S' else sv:02d}"
        t = 1900 * SECONDS_PER_WEEK + float(fields[column["(rcvTow)"]])
        r = index[(t, sat)]
        slot = int(fields[column["(freqId)"]]) - 7
        frequency = 1602.0e6 + 0.5625e6 * slot if system == "R" else 1575.42e6
        wavelength = SPEED_OF_LIGHT / frequency
        assert obs.row_fields["range_rate_mps"][r] == pytest.approx(
            -wavelength * float(fields[column["(doMes)"]]), rel=1e-14
        )
        assert obs.row_fields["range_rate_sigma_mps"][r] == pytest.approx(
            wavelength * float(fields[column["(doStdev)"]]), rel=1e-14
        )
        assert obs.row_fields["nlos"][r] == {"0": 0, "1": 1, "#": -1}[fields[column["NLOS"]]]
    labels = obs.row_fields["nlos"][doppler]
    assert [(labels == v).sum() for v in (1, 0, -1)] == [263, 279, 3]
    assert recording.glonass_channels == {1: 1, 2: -4, 9: -6, 10: -7, 11: 0, 19: 3, 20: 2, 21: 4}
