"""Android Raw records → observations on hand-built records: the exact pseudorange of each
system's clock rule (GPS week, BeiDou time, GLONASS day), Doppler, carrier phase and C/N0 rows
with the receiver's σ, signal codes and satellite numbers, and the rows dropped and counted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT as C
from vo_doppler.io.android_raw import (
    NANOS_PER_DAY,
    NANOS_PER_WEEK,
    RawColumns,
    numbered,
    raw_observations,
    satellite_ids,
    signal_codes,
)

L1, E5, B1I = 1575.42e6, 1176.45e6, 1561.098e6
GLONASS_K = -3
G1 = 1602.0e6 + GLONASS_K * 0.5625e6
TIME_NANOS = 10**12
WHOLE = 2300 * NANOS_PER_WEEK + 3600 * 10**9 + 5 * 10**8  # GPS ns of the epoch
BIAS_NS = 1500.5  # large enough to show in the epoch time (float64 at 1.4e9 s: 0.24 µs)
LEAP_S = 18
WEEK_OK, DAY_OK, AMBIGUOUS = 1 | 8, 1 | 128, 1 | 8 | 16


def _receive(system: str, whole: int = WHOLE) -> int:
    """The receiver's time in the satellite's time scale (ns): GPS time of week, BeiDou time of
    week, or the GLONASS time of day (UTC(SU) = UTC + 3 h)."""
    week = whole % NANOS_PER_WEEK
    if system == "C":
        return week - 14 * 10**9
    if system == "R":
        return (whole % NANOS_PER_DAY + 3 * 3600 * 10**9 - LEAP_S * 10**9) % NANOS_PER_DAY
    return week


def _raw(rows: list[dict], whole: list[int] | None = None) -> RawColumns:
    """Raw columns of ``rows`` (each: constellation, svid, frequency, travel_ns and optional
    fields), every row at the epoch ``WHOLE`` unless ``whole`` gives each row's."""
    whole = whole or [WHOLE] * len(rows)
    system = {1: "G", 3: "R", 5: "C", 6: "E", 4: "J", 2: "S"}

    def column(name, default):
        return np.array([row.get(name, default) for row in rows])

    received = [
        _receive(system.get(row["constellation"], "G"), w) - row.get("travel_ns", 70_000_000)
        for row, w in zip(rows, whole, strict=True)
    ]
    return RawColumns(
        path=Path("raw.txt"),
        line=np.arange(len(rows)) + 10,
        constellation=column("constellation", 1).astype(float),
        svid=column("svid", 1).astype(float),
        state=column("state", WEEK_OK).astype(float),
        time_nanos=np.full(len(rows), TIME_NANOS, dtype=np.int64),
        full_bias_nanos=TIME_NANOS - np.array(whole, dtype=np.int64),
        bias_nanos=np.full(len(rows), BIAS_NS),
        time_offset_nanos=np.zeros(len(rows)),
        received_sv_time_nanos=np.array(received, dtype=np.int64),
        received_sv_time_uncertainty_nanos=column("sv_time_sigma_ns", 10.0).astype(float),
        cn0=column("cn0", 40.0).astype(float),
        prr=column("prr", -500.0).astype(float),
        prr_uncertainty=column("prr_sigma", 0.05).astype(float),
        adr_state=column("adr_state", 1).astype(float),
        adr=column("adr", 1000.0).astype(float),
        frequency=column("frequency", L1).astype(float),
        code_type=column("code_type", "C").astype(str),
        leap_second=np.full(len(rows), float(LEAP_S)),
        clock_discontinuity=column("discontinuity", 0).astype(float),
    )


def _row(obs, system: str, prn: int, code: str):
    hit = (obs.system == system) & (obs.prn == prn) & (np.array(obs.codes)[obs.code] == code)
    (index,) = np.flatnonzero(hit)
    return obs.value[index], obs.lli[index]


def test_each_systems_clock_rule_gives_the_exact_pseudorange():
    rows = [
        {"constellation": 1, "svid": 5, "travel_ns": 70_000_000},
        {"constellation": 6, "svid": 11, "frequency": E5, "code_type": "", "travel_ns": 80_000_000},
        {
            "constellation": 5,
            "svid": 20,
            "frequency": B1I,
            "code_type": "",
            "travel_ns": 75_000_000,
        },
        {"constellation": 3, "svid": 7, "frequency": G1, "state": DAY_OK, "travel_ns": 68_000_000},
    ]
    problems: list[str] = []
    obs, _ = raw_observations(_raw(rows), "phone", problems)
    np.testing.assert_array_equal(obs.epoch_time, [WHOLE * 1e-9 - BIAS_NS * 1e-9])
    for (system, prn, code), travel_ns in zip(
        [("G", 5, "C1C"), ("E", 11, "C5Q"), ("C", 20, "C2I"), ("R", 7, "C1C")],
        [70e6, 80e6, 75e6, 68e6],
        strict=True,
    ):
        value, _ = _row(obs, system, prn, code)
        assert value == pytest.approx((travel_ns - BIAS_NS) * 1e-9 * C, rel=1e-12), system
    assert obs.header.glonass_channels == {7: GLONASS_K}
    assert problems == []


def test_doppler_carrier_phase_cn0_and_the_receivers_sigma():
    row = {"constellation": 1, "svid": 5, "prr": -500.0, "prr_sigma": 0.05, "adr": 1000.0}
    obs, sigma = raw_observations(_raw([row]), "phone", [])
    assert _row(obs, "G", 5, "D1C") == (pytest.approx(500.0 * L1 / C, rel=1e-12), -1)
    assert _row(obs, "G", 5, "L1C") == (pytest.approx(1000.0 * L1 / C, rel=1e-12), 0)
    assert _row(obs, "G", 5, "S1C") == (40.0, -1)
    t = obs.epoch_time[0]
    got = sigma.at([t, t, t], np.array(["G", "G", "G"]), [5, 5, 5], ["D1C", "C1C", "L1C"])
    np.testing.assert_allclose(got[:2], [0.05 * L1 / C, 10e-9 * C], rtol=1e-12)
    assert np.isnan(got[2])


def test_a_slip_a_reset_or_a_clock_discontinuity_marks_the_carrier_phase():
    rows = [
        {"constellation": 1, "svid": 5},
        {"constellation": 1, "svid": 6, "adr_state": 1 | 4},  # cycle slip
        {"constellation": 1, "svid": 5, "discontinuity": 1},  # next epoch: the clock restarted
        {"constellation": 1, "svid": 6, "discontinuity": 1, "adr_state": 0},  # no valid phase
    ]
    whole = [WHOLE, WHOLE, WHOLE + 10**9, WHOLE + 10**9]
    obs, _ = raw_observations(_raw(rows, whole), "phone", [])
    carrier = np.array(obs.codes)[obs.code] == "L1C"
    rows = zip(obs.prn[carrier], obs.time[carrier] - obs.time[0], obs.lli[carrier], strict=True)
    assert list(rows) == [
        (5, 0.0, 0),
        (6, 0.0, 1),
        (5, 1.0, 1),
    ]


def test_unusable_rows_are_dropped_and_counted():
    rows = [
        {"constellation": 1, "svid": 5},
        {"constellation": 0, "svid": 5},  # unknown constellation
        {"constellation": 3, "svid": 95, "frequency": G1, "state": DAY_OK},  # unknown slot
        {"constellation": 1, "svid": 40},  # no such GPS PRN
        {"constellation": 1, "svid": 7, "frequency": 1.5e9},  # no GPS band there
        {"constellation": 1, "svid": 8, "state": AMBIGUOUS, "prr_sigma": C},  # phone's "unknown"
        {"constellation": 1, "svid": 9, "travel_ns": 600_000_000},  # beyond 0.5 s
        {"constellation": 1, "svid": 10, "cn0": 120.0},
    ]
    problems: list[str] = []
    obs, _ = raw_observations(_raw(rows), "phone", problems)
    assert problems == [
        "raw.txt: 4 Raw rows of unknown constellation, satellite or signal",
        "raw.txt: 1 pseudoranges outside 1 ms-0.5 s dropped",
        "raw.txt: 1 Doppler rows without a usable uncertainty",
        "raw.txt: 1 C/N0 outside 0-100 dB-Hz",
    ]
    codes = np.array(obs.codes)[obs.code]
    kept = sorted({(int(p), str(c)) for p, c in zip(obs.prn, codes, strict=True)})
    assert kept == [
        (5, "C1C"), (5, "D1C"), (5, "L1C"), (5, "S1C"),
        (8, "L1C"), (8, "S1C"),  # ambiguous: no pseudorange; no σ: no Doppler
        (9, "D1C"), (9, "L1C"), (9, "S1C"),
        (10, "C1C"), (10, "D1C"), (10, "L1C"),
    ]  # fmt: skip


def test_an_epoch_earlier_than_the_one_before_names_its_line():
    rows = [{"constellation": 1, "svid": 5}, {"constellation": 1, "svid": 6}]
    with pytest.raises(InputError, match=r"^raw\.txt:11: Raw record earlier than the one before"):
        raw_observations(_raw(rows, [WHOLE, WHOLE - 10**9]), "phone", [])


def test_signal_codes_from_frequency_and_code_type():
    system = np.array(["G", "G", "E", "C", "C", "R", "J", "I", "G"])
    frequency = np.array([L1, E5, E5, B1I, E5, G1, 1278.75e6, E5, 1.5e9])
    code_type = np.array(["C", "", "X", "", "", "", "", "", "C"])
    np.testing.assert_array_equal(
        signal_codes(system, frequency, code_type),
        ["1C", "5Q", "5X", "2I", "5P", "1C", "6C", "5A", ""],
    )


def test_satellite_numbers_of_sbas_and_qzss_and_their_ranges():
    system, prn = satellite_ids(np.array([1, 2, 4, 3, 9]), np.array([5, 131, 194, 24, 1]))
    np.testing.assert_array_equal(system, ["G", "S", "J", "R", ""])
    np.testing.assert_array_equal(prn, [5, 31, 2, 24, 1])
    np.testing.assert_array_equal(
        numbered(
            np.array(["G", "G", "S", "S", "J", "R", ""]), np.array([32, 33, 20, 19, 2, 28, 1])
        ),
        [True, False, True, False, True, False, False],
    )
