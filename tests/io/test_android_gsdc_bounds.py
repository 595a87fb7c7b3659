"""Android GnssLogger and GSDC ``device_gnss.csv`` values no receiver or satellite can have: a
C/N0 of −1 or −1e308, a pseudorange rate of 1e20 m/s, an uncertainty of −1e308, 0 or inf, Svid
0, a satellite speed, clock drift or signal travel time off any GNSS satellite's; and a gyro
time repeated. Measurements are dropped and counted (never a σ of −inf), satellite states
dropped and counted, the repeated time an InputError naming file and line."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import shared_data_dir
from tests.io.test_android import CHIPSET, L1, RAW, synthetic_rows, write_log
from vo_doppler.bounds import CN0, MEASUREMENT_SIGMA
from vo_doppler.errors import InputError
from vo_doppler.io.android import read_gnsslogger
from vo_doppler.io.gsdc import REQUIRED, read_device_gnss

GPS_NS = 1_300_000_000 * 10**9
SATELLITES = (3, 7, 12, 19, 25)
COLUMNS = (
    "utcTimeMillis",
    "Svid",
    "ConstellationType",
    "State",
    "Cn0DbHz",
    "PseudorangeRateMetersPerSecond",
    "PseudorangeRateUncertaintyMetersPerSecond",
    "ReceivedSvTimeUncertaintyNanos",
    "AccumulatedDeltaRangeState",
    "AccumulatedDeltaRangeMeters",
    "CarrierFrequencyHz",
    "CodeType",
    *REQUIRED,
    *(f"WlsPosition{a}EcefMeters" for a in "XYZ"),
)


def gsdc_row(k: int, epoch: int, **changed: str) -> dict[str, str]:
    """One GPS L1 row of a plausible device_gnss.csv (satellite ``SATELLITES[k]``)."""
    angle = 0.7 * k
    position = 2.66e7 * np.array([np.cos(angle), np.sin(angle), 0.3]) / np.hypot(1.0, 0.3)
    velocity = 3.0e3 * np.array([-np.sin(angle), np.cos(angle), 0.0])
    row = {
        "utcTimeMillis": str(1_600_000_000_000 + 1000 * epoch),
        "Svid": str(SATELLITES[k]),
        "ConstellationType": "1",
        "State": "16431",
        "Cn0DbHz": "40.5",
        "PseudorangeRateMetersPerSecond": repr(-300.0 + 100.0 * k),
        "PseudorangeRateUncertaintyMetersPerSecond": "0.05",
        "ReceivedSvTimeUncertaintyNanos": "10",
        "AccumulatedDeltaRangeState": "16",
        "AccumulatedDeltaRangeMeters": "0",
        "CarrierFrequencyHz": repr(L1),
        "CodeType": "C",
        "ArrivalTimeNanosSinceGpsEpoch": str(GPS_NS + epoch * 10**9),
        "RawPseudorangeMeters": repr(2.1e7 + 1.0e6 * k),
        **{
            f"SvPosition{a}EcefMeters": repr(float(v)) for a, v in zip("XYZ", position, strict=True)
        },
        **{
            f"SvVelocity{a}EcefMetersPerSecond": repr(float(v))
            for a, v in zip("XYZ", velocity, strict=True)
        },
        "SvClockBiasMeters": "1500.0",
        "SvClockDriftMetersPerSecond": "0.001",
        "WlsPositionXEcefMeters": "-2694685.0",
        "WlsPositionYEcefMeters": "-4293642.0",
        "WlsPositionZEcefMeters": "3857878.0",
    }
    row.update(changed)
    return row


def write_gsdc(tmp_path, rows: list[dict[str, str]]):
    path = tmp_path / "device_gnss.csv"
    lines = ["MessageType," + ",".join(COLUMNS)]
    lines += ["Raw," + ",".join(row.get(c, "") for c in COLUMNS) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def gsdc_with(column: str, value: str) -> list[dict[str, str]]:
    rows = [gsdc_row(k, e) for e in range(2) for k in range(len(SATELLITES))]
    rows[6] = {**rows[6], column: value}  # second epoch, satellite 7
    return rows


def test_the_synthetic_table_reads_whole(tmp_path):
    recording = read_device_gnss(write_gsdc(tmp_path, gsdc_with("Cn0DbHz", "40.5")))
    assert len(recording.satellites.time) == 10
    assert recording.observations.select(code="D1C").value.size == 10


@pytest.mark.parametrize(
    ("column", "value", "code"),
    [
        ("Cn0DbHz", "-1", "S1C"),
        ("Cn0DbHz", "-1e308", "S1C"),
        ("PseudorangeRateMetersPerSecond", "1e20", "D1C"),
        ("PseudorangeRateUncertaintyMetersPerSecond", "0", "D1C"),
        ("PseudorangeRateUncertaintyMetersPerSecond", "inf", "D1C"),
        ("PseudorangeRateUncertaintyMetersPerSecond", "-1e308", "D1C"),
    ],
)
def test_an_impossible_measurement_is_dropped_and_counted(tmp_path, column, value, code):
    recording = read_device_gnss(write_gsdc(tmp_path, gsdc_with(column, value)))
    assert recording.observations.select(code=code).value.size == 9
    assert any(str(tmp_path) in p for p in recording.problems)
    sigma = recording.sigma.sigma[np.isfinite(recording.sigma.sigma)]
    assert (sigma > 0).all()


@pytest.mark.parametrize(
    ("column", "value"),
    [
        ("Svid", "0"),
        ("SvClockDriftMetersPerSecond", "9e18"),
        ("SvClockBiasMeters", "1e12"),
        ("SvVelocityXEcefMetersPerSecond", "1e6"),
        ("RawPseudorangeMeters", "1e12"),
    ],
)
def test_an_impossible_satellite_state_is_dropped_and_counted(tmp_path, column, value):
    recording = read_device_gnss(write_gsdc(tmp_path, gsdc_with(column, value)))
    assert len(recording.satellites.time) == 9
    assert any("no GNSS satellite has dropped (first: line 8)" in p for p in recording.problems)
    if column == "Svid":
        assert 0 not in recording.observations.prn


def test_android_uncertainty_and_cn0_of_minus_1e308_are_dropped(tmp_path):
    rows = synthetic_rows()
    fields = rows[0].split(",")
    fields[1 + RAW.index("PseudorangeRateUncertaintyMetersPerSecond")] = "-1e308"
    fields[1 + RAW.index("Cn0DbHz")] = "-1e308"
    rows[0] = ",".join(fields)
    log = read_gnsslogger(write_log(tmp_path, rows))
    assert np.isfinite(log.sigma.sigma[~np.isnan(log.sigma.sigma)]).all()
    assert not CN0.outside(log.observations.select(code="S1C").value).any()
    assert not np.isin(7, log.observations.select(system="G", code="D1C").prn), (
        "the row with σ = −1e308"
    )


def test_a_repeated_gyro_time_names_the_line(tmp_path):
    gyro = [f"UncalGyro,0,{CHIPSET + k * 10**7},0.0,0.0,0.1,0,0,0" for k in range(5)]
    gyro.insert(3, gyro[2])
    accel = [f"UncalAccel,0,{CHIPSET},0.0,0.0,9.81,0,0,0"]
    path = write_log(tmp_path, synthetic_rows() + gyro + accel)
    line = 1 + len(path.read_text().splitlines()) - len(gyro) - len(accel) + 3
    with pytest.raises(InputError, match=rf"gnss_log\.txt:{line}: sensor row not after"):
        read_gnsslogger(path)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    column=st.sampled_from(COLUMNS[4:8] + REQUIRED),
    value=st.sampled_from(["-1", "0", "1e20", "-1e308", "inf", "nan", "9e18"]),
)
def test_any_odd_number_reads_to_possible_values_or_an_input_error(tmp_path, column, value):
    try:
        recording = read_device_gnss(write_gsdc(tmp_path, gsdc_with(column, value)))
    except InputError as exc:
        assert str(tmp_path) in str(exc)
        return
    sigma = recording.sigma.sigma[~np.isnan(recording.sigma.sigma)]
    assert not MEASUREMENT_SIGMA.outside(sigma).any()
    assert np.isfinite(recording.observations.value).all()
    table = recording.satellites
    assert (np.abs(table.clock_drift) < 1e-6).all()
    assert ((table.travel_time_s > 1e-3) & (table.travel_time_s < 0.5)).all()


def test_the_real_table_still_reads():
    path = shared_data_dir() / "android_pixel7pro" / "device_gnss.csv"
    if not path.is_file():
        pytest.skip(f"{path} absent")
    assert len(read_device_gnss(path).satellites.time) > 0
