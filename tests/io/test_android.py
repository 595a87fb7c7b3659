"""Android GnssLogger reader: clock rules, Doppler sign and gyro mounting on synthetic logs;
the real Pixel 7 Pro / Pixel 6 logs read, and agree with GSDC's derived pseudoranges."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.signals import wavelengths
from vo_doppler.io.android import read_gnsslogger, up_axis
from vo_doppler.io.gsdc import read_device_gnss

RAW_HEADER = (
    "utcTimeMillis,TimeNanos,LeapSecond,TimeUncertaintyNanos,FullBiasNanos,BiasNanos,"
    "BiasUncertaintyNanos,DriftNanosPerSecond,DriftUncertaintyNanosPerSecond,"
    "HardwareClockDiscontinuityCount,Svid,TimeOffsetNanos,State,ReceivedSvTimeNanos,"
    "ReceivedSvTimeUncertaintyNanos,Cn0DbHz,PseudorangeRateMetersPerSecond,"
    "PseudorangeRateUncertaintyMetersPerSecond,AccumulatedDeltaRangeState,"
    "AccumulatedDeltaRangeMeters,AccumulatedDeltaRangeUncertaintyMeters,CarrierFrequencyHz,"
    "CarrierCycles,CarrierPhase,CarrierPhaseUncertainty,MultipathIndicator,SnrInDb,"
    "ConstellationType,AgcDb,BasebandCn0DbHz,FullInterSignalBiasNanos,"
    "FullInterSignalBiasUncertaintyNanos,SatelliteInterSignalBiasNanos,"
    "SatelliteInterSignalBiasUncertaintyNanos,CodeType,ChipsetElapsedRealtimeNanos"
)
RAW = RAW_HEADER.split(",")
HEADER = "\n".join(
    [
        "# Header Description:",
        "#",
        "# Raw," + ",".join(RAW),
        "# UncalGyro,utcTimeMillis,elapsedRealtimeNanos,UncalGyroXRadPerSec,UncalGyroYRadPerSec,"
        "UncalGyroZRadPerSec,DriftXRadPerSec,DriftYRadPerSec,DriftZRadPerSec",
        "# UncalAccel,utcTimeMillis,elapsedRealtimeNanos,UncalAccelXMps2,UncalAccelYMps2,"
        "UncalAccelZMps2,BiasXMps2,BiasYMps2,BiasZMps2",
        "# Nav,Svid,Type,Status,MessageId,Sub-messageId,Data(Bytes)",
        "#",
    ]
)
WEEK_NS = 604800 * 10**9
DAY_NS = 86400 * 10**9
TIME_NANOS = 5_000_000_000_000
GPS_NS = 2200 * WEEK_NS + 345_600 * 10**9 + 123_456_789  # receiver's GPS time of the epoch
FULL_BIAS = TIME_NANOS - GPS_NS - 1  # with BiasNanos 0.25: t_Rx = GPS_NS + 0.75 ns
BIAS = 0.25
CHIPSET = 16_000_000_000_000
BDT_NS = 14 * 10**9  # BDT = GPST − 14 s
B1I = 1561.098e6
L1, L5, G1 = 1575.42e6, 1176.45e6, 1602.0e6 + 3 * 0.5625e6


def raw_row(
    svid, constellation, state, received, prr, frequency, epoch=0, code="C", adr=0.0, resets=0
):
    values = dict.fromkeys(RAW, "")
    values.update(
        utcTimeMillis=str(1_700_000_000_000 + 1000 * epoch),
        TimeNanos=str(TIME_NANOS + epoch * 10**9),
        FullBiasNanos=str(FULL_BIAS),
        BiasNanos=str(BIAS),
        Svid=str(svid),
        HardwareClockDiscontinuityCount=str(resets),
        TimeOffsetNanos="0.0",
        State=str(state),
        ReceivedSvTimeNanos=str(received + epoch * 10**9),
        ReceivedSvTimeUncertaintyNanos="12",
        Cn0DbHz="41.5",
        PseudorangeRateMetersPerSecond=repr(prr),
        PseudorangeRateUncertaintyMetersPerSecond="0.25",
        AccumulatedDeltaRangeState="1" if adr else "16",
        AccumulatedDeltaRangeMeters=repr(adr),
        CarrierFrequencyHz=repr(frequency),
        ConstellationType=str(constellation),
        CodeType=code,
        ChipsetElapsedRealtimeNanos=str(CHIPSET + epoch * 10**9),
    )
    return "Raw," + ",".join(values[name] for name in RAW)


def t_rx_mod(period: int) -> int:
    return (TIME_NANOS - FULL_BIAS) % period


def synthetic_rows(epoch: int = 0, resets: int = 0) -> list[str]:
    """Raw rows of one epoch (and a Nav row, whose data bytes outnumber its header's columns)."""
    tow = t_rx_mod(WEEK_NS)
    glonass_tod = (t_rx_mod(DAY_NS) + 3 * 3600 * 10**9 - 18 * 10**9) % DAY_NS
    return [
        raw_row(7, 1, 16431, tow - 70_000_000, 123.456, L1, epoch, adr=-2.5e4, resets=resets),
        raw_row(7, 1, 81921, t_rx_mod(WEEK_NS) - 70_000_004, 123.5, L5, epoch, code="Q"),
        raw_row(12, 5, 16431, t_rx_mod(WEEK_NS) - BDT_NS - 75_000_000, -50.0, B1I, epoch, code="I"),
        raw_row(4, 3, 227, glonass_tod - 68_000_000, 600.0, G1, epoch),
        raw_row(21, 6, 1 | 1024 | 2048, 12_345, -321.0, L1, epoch),
        raw_row(9, 1, 1 | 16, t_rx_mod(WEEK_NS) - 72_000_000, 10.0, L1, epoch),
        "Nav,5,257,1,-1,4,-117,0,12,34,-56,78,90,1,2,3,4,5",
    ]  # fmt: skip


def write_log(tmp_path, lines, name="gnss_log.txt"):
    path = tmp_path / name
    path.write_text(HEADER + "\n" + "\n".join(lines) + "\n")
    return path


def value(obs, system, prn, code):
    rows = obs.mask(system, code) & (obs.prn == prn)
    assert rows.sum() == 1, (system, prn, code)
    return obs.value[rows][0]


def test_clock_rules_give_exact_pseudoranges_per_constellation(tmp_path):
    log = read_gnsslogger(write_log(tmp_path, synthetic_rows()))
    obs = log.observations
    assert obs.epoch_time[0] == pytest.approx((GPS_NS + 0.75) * 1e-9, abs=1e-6)
    c_ns = SPEED_OF_LIGHT * 1e-9
    assert value(obs, "G", 7, "C1C") == pytest.approx((70_000_000 - 0.25) * c_ns, abs=1e-6)
    assert value(obs, "G", 7, "C5Q") == pytest.approx((70_000_004 - 0.25) * c_ns, abs=1e-6)
    assert value(obs, "C", 12, "C2I") == pytest.approx((75_000_000 - 0.25) * c_ns, abs=1e-6)
    assert value(obs, "R", 4, "C1C") == pytest.approx((68_000_000 - 0.25) * c_ns, abs=1e-6)
    # Galileo without TOW (100-ms ambiguity) and GPS with MSEC_AMBIGUOUS: no pseudorange
    assert "C1C" not in [obs.codes[i] for i in obs.code[obs.system == "E"]]
    assert not np.any(obs.mask("G", "C1C") & (obs.prn == 9))
    assert np.any(obs.mask("G", "D1C") & (obs.prn == 9))
    assert obs.header.glonass_channels == {4: 3}
    assert value(obs, "G", 7, "L1C") == pytest.approx(-2.5e4 * L1 / SPEED_OF_LIGHT, rel=1e-15)
    assert value(obs, "G", 7, "S1C") == 41.5


def test_doppler_round_trips_through_the_gnss_stage_sign_and_wavelength(tmp_path):
    obs = read_gnsslogger(write_log(tmp_path, synthetic_rows())).observations
    for system, prn, code, prr in (
        ("G", 7, "D1C", 123.456),
        ("G", 7, "D5Q", 123.5),
        ("C", 12, "D2I", -50.0),
        ("R", 4, "D1C", 600.0),
        ("E", 21, "D1C", -321.0),
    ):
        doppler = value(obs, system, prn, code)
        wavelength = wavelengths(
            np.array([system]), np.array([prn]), code, obs.header.glonass_channels
        )
        assert -wavelength[0] * doppler == pytest.approx(prr, rel=1e-12), (system, code)


def test_carrier_lli_after_a_clock_discontinuity(tmp_path):
    lines = synthetic_rows(0) + synthetic_rows(1) + synthetic_rows(2, resets=1)
    obs = read_gnsslogger(write_log(tmp_path, lines)).observations
    np.testing.assert_array_equal(obs.select("G", "L1C").lli, [0, 0, 1])


def test_reported_doppler_sigma_is_kept_in_hz(tmp_path):
    log = read_gnsslogger(write_log(tmp_path, synthetic_rows()))
    t = log.observations.epoch_time[0]
    sigma = log.sigma.at([t, t], ["G", "G"], [7, 7], ["D1C", "C1C"])
    np.testing.assert_allclose(sigma, [0.25 * L1 / SPEED_OF_LIGHT, 12e-9 * SPEED_OF_LIGHT])


def test_time_going_back_names_the_line(tmp_path):
    lines = synthetic_rows(1) + synthetic_rows(0)
    with pytest.raises(InputError, match=r"gnss_log.txt:15: Raw record earlier"):
        read_gnsslogger(write_log(tmp_path, lines))


def test_bad_number_and_unknown_record_name_the_line(tmp_path):
    lines = synthetic_rows()
    lines[2] = lines[2].replace("41.5", "4x.5")
    with pytest.raises(InputError, match=r"gnss_log.txt:10: Cn0DbHz is not a number"):
        read_gnsslogger(write_log(tmp_path, lines))
    with pytest.raises(InputError, match=r"gnss_log.txt:8: record type 'Bogus'"):
        read_gnsslogger(write_log(tmp_path, ["Bogus,1,2", *synthetic_rows()]))


def _gyro_lines(mounting: np.ndarray, n: int = 400):
    """Vehicle turning (yaw rate 0.3 sin t) with small roll/pitch rates, seen by the phone."""
    rng = np.random.default_rng(3)
    t = np.arange(n) * 0.02
    yaw_rate = 0.3 * np.sin(t)
    vehicle = np.stack([0.01 * rng.standard_normal(n), 0.01 * rng.standard_normal(n), yaw_rate], 1)
    phone = vehicle @ mounting  # ω_phone = Rᵀ ω_vehicle, rows
    gravity = ",".join(repr(float(g)) for g in np.array([0.0, 0.0, 9.81]) @ mounting)
    lines = []
    for k in range(n):
        elapsed = CHIPSET + int(t[k] * 1e9)
        rates = ",".join(repr(float(w)) for w in phone[k])
        lines.append(f"UncalGyro,0,{elapsed},{rates},0,0,0")
        lines.append(f"UncalAccel,0,{elapsed},{gravity},0,0,0")
    return t, yaw_rate, lines


def test_gyro_yaw_rate_through_given_and_estimated_mounting(tmp_path):
    mounting = Rotation.from_euler("zyx", [0.7, -1.2, 2.0]).as_matrix()  # phone → vehicle
    t, yaw_rate, lines = _gyro_lines(mounting)
    path = write_log(tmp_path, synthetic_rows() + lines)
    given = read_gnsslogger(path, mounting=mounting)
    np.testing.assert_allclose(given.yaw_rate.value, yaw_rate, atol=1e-12)
    gps0 = (GPS_NS + 0.75) * 1e-9
    np.testing.assert_allclose(given.yaw_rate.t - gps0, t, atol=1e-6)
    assert given.mounting_method == "given"
    estimated = read_gnsslogger(path)
    assert estimated.mounting_method.startswith("largest angular-rate variance")
    assert np.degrees(np.arccos(estimated.up_axis @ mounting[2])) < 1.0
    assert np.max(np.abs(estimated.yaw_rate.value - yaw_rate)) < 0.003


def test_static_gyro_falls_back_to_gravity_and_needs_an_accelerometer(tmp_path):
    omega = np.random.default_rng(1).normal(0, 1e-3, (50, 3))
    up, method = up_axis(omega, np.array([[0.1, 0.2, 9.8]]), None, tmp_path)
    assert method == "mean accelerometer direction"
    np.testing.assert_allclose(up, np.array([0.1, 0.2, 9.8]) / np.linalg.norm([0.1, 0.2, 9.8]))
    with pytest.raises(InputError, match="give the mounting rotation"):
        up_axis(omega, None, None, tmp_path)
    with pytest.raises(InputError, match="3×3 rotation"):
        up_axis(omega, None, np.eye(3) * 2, tmp_path)


@pytest.mark.shared_data
def test_pixel7pro_log_agrees_with_gsdc_derived_pseudoranges():
    log = read_gnsslogger(require_shared("android_pixel7pro/gnss_log.txt"))
    gsdc = read_device_gnss(require_shared("android_pixel7pro/device_gnss.csv"))
    ours, theirs = log.observations.select(code="C1C"), gsdc.observations.select(code="C1C")
    assert len(ours) == len(theirs) == 80
    np.testing.assert_array_equal(ours.satellites(), theirs.satellites())
    assert set(ours.system) == {"G", "R"}
    difference = theirs.value - ours.value
    for epoch in np.unique(ours.time):
        rows = ours.time == epoch
        # GSDC's arrival time carries the clock drift: a common offset per epoch, same to 1 mm
        assert np.ptp(difference[rows]) < 1e-3
    for code in ("D1C", "L1C", "D5Q", "L5Q"):
        a, b = log.observations.select(code=code), gsdc.observations.select(code=code)
        epoch_a = np.searchsorted(a.epoch_time, a.time)
        epoch_b = np.searchsorted(b.epoch_time, b.time)
        mine = dict(zip(zip(epoch_a, a.satellites(), strict=True), a.value, strict=True))
        theirs = dict(zip(zip(epoch_b, b.satellites(), strict=True), b.value, strict=True))
        common = sorted(set(mine) & set(theirs))
        assert len(common) >= len(theirs) - 1, code
        np.testing.assert_allclose(
            [mine[k] for k in common], [theirs[k] for k in common], rtol=1e-12, err_msg=code
        )


@pytest.mark.shared_data
def test_pixel6_log_with_gyro_rows():
    log = read_gnsslogger(require_shared("android_pixel7pro/pixel6_gnsslogger.txt"))
    obs = log.observations
    assert obs.epoch_time.size == 31
    assert set(obs.system) >= {"G", "R", "E"}
    assert np.all(np.diff(obs.epoch_time) > 0.9)
    doppler = obs.select(code="D1C")
    assert np.all(np.abs(doppler.value) < 6000.0)  # |D| of a static receiver < 5 kHz at L1
    assert len(log.yaw_rate) == 10
    raw_span = (obs.epoch_time[0] - 60.0, obs.epoch_time[-1] + 300.0)
    assert np.all((log.yaw_rate.t > raw_span[0]) & (log.yaw_rate.t < raw_span[1]))
    assert log.mounting_method == "mean accelerometer direction"
    assert log.up_axis[2] > 0.9  # the phone lay roughly flat, screen up


BASE_LOG = HEADER + "\n" + "\n".join(synthetic_rows(0) + synthetic_rows(1)) + "\n"


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    edits=st.lists(
        st.tuples(
            st.integers(0, len(BASE_LOG) - 1),
            st.sampled_from([",", "x", "\n", "-", "9", "", "é", "\x00"]),
        ),
        min_size=1,
        max_size=8,
    )
)
def test_corrupted_logs_fail_only_with_input_errors(tmp_path, edits):
    text = BASE_LOG
    for position, replacement in edits:
        text = text[:position] + replacement + text[position + 1 :]
    path = tmp_path / "gnss_log.txt"
    path.write_text(text, encoding="utf-8")
    try:
        log = read_gnsslogger(path)
    except InputError as exc:
        assert "gnss_log.txt" in str(exc)
        return
    assert np.all(np.isfinite(log.observations.value))
    assert np.all(np.diff(log.observations.epoch_time) > 0)


def test_clock_fields_that_overflow_name_the_line(tmp_path):
    lines = synthetic_rows()
    lines[0] = lines[0].replace(f",{FULL_BIAS},", f",{-(2**63) + 5},")
    with pytest.raises(InputError, match=r"gnss_log.txt:8: TimeNanos − FullBiasNanos overflows"):
        read_gnsslogger(write_log(tmp_path, lines))
