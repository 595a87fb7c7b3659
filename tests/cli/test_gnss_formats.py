"""``vo-doppler gnss velocity`` on a u-blox UBX log built with pyubx2: a GPS-like constellation
broadcast in RXM-SFRBX subframes, RXM-RAWX pseudoranges and Doppler of a receiver moving at a
known velocity. No --nav: the ephemerides come from the log. The velocity comes back."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from pyubx2 import UBXMessage

from tests.conftest import require_shared
from tests.helpers.lnav import EXAMPLE, encode_ephemeris, with_parity
from tests.io.test_android import synthetic_rows, write_log
from vo_doppler.cli import main
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT, ecef_to_enu_rotation, geodetic_to_ecef
from vo_doppler.gnss.satellite_source import transmit_states
from vo_doppler.gnss.spp import elevation_azimuth
from vo_doppler.io.gnss_csv import VELOCITY_COLUMNS
from vo_doppler.io.receiver_file import read_observation_file, sniff_format
from vo_doppler.io.ubx import read_ubx

WEEK = 2200
T0_SOW = 345_660.0
LAT, LON = np.radians(35.0), np.radians(139.0)
VELOCITY_ENU = np.array([10.0, 5.0, 0.0])
CLOCK_BIAS_S, CLOCK_DRIFT = 1.0e-4, 2.0e-8
L1_WAVELENGTH = SPEED_OF_LIGHT / 1575.42e6


def _constellation() -> bytes:
    """24 satellites, 3 planes × 8 slots, each broadcast as subframes 1–3."""
    frames = []
    for k in range(24):
        plane, slot = divmod(k, 8)
        eph = dict(EXAMPLE)
        eph["m0"] = np.angle(np.exp(1j * (EXAMPLE["m0"] + slot * 2 * np.pi / 8 + plane * 0.5)))
        eph["omega0"] = np.angle(np.exp(1j * (EXAMPLE["omega0"] + plane * 2 * np.pi / 3)))
        eph["iodc"] = 10 + k
        for words in encode_ephemeris(eph, 57599):
            dwrd = {f"dwrd_{i + 1:02d}": w for i, w in enumerate(with_parity(words))}
            frames.append(
                UBXMessage(
                    "RXM", "RXM-SFRBX", 0, gnssId=0, svId=k + 1, numWords=10, version=2, **dwrd
                ).serialize()
            )
    return b"".join(frames)


def _rawx(tow: float, rows: list[tuple[int, float, float]]) -> bytes:
    fields = {}
    for i, (prn, pseudorange, doppler) in enumerate(rows, start=1):
        fields |= {
            f"prMes_{i:02d}": pseudorange, f"doMes_{i:02d}": doppler, f"gnssId_{i:02d}": 0,
            f"svId_{i:02d}": prn, f"cno_{i:02d}": 45, f"prValid_{i:02d}": 1,
            f"locktime_{i:02d}": 10_000,
        }  # fmt: skip
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=tow, week=WEEK, leapS=18, numMeas=len(rows), version=1,
        **fields,
    ).serialize()  # fmt: skip


def _log(tmp_path):
    subframes = _constellation()
    dummy = tmp_path / "nav_only.ubx"
    dummy.write_bytes(_rawx(T0_SOW, []) + subframes)
    nav = read_ubx(dummy).navigation
    assert len(nav.kepler) == 24
    rotation = ecef_to_enu_rotation(LAT, LON)
    velocity = rotation.T @ VELOCITY_ENU
    start = geodetic_to_ecef(LAT, LON, 50.0)
    messages = []
    for n in range(5):
        t = WEEK * 604800.0 + T0_SOW + n
        receiver = start + velocity * n
        prns = np.arange(1, 25)
        states, _ = transmit_states(nav, "G", prns, t, receiver_ecef=receiver)
        vector = states.position - receiver
        distance = np.linalg.norm(vector, axis=1)
        los = vector / distance[:, None]
        elevation, _ = elevation_azimuth(receiver, los)
        up = elevation > np.radians(15.0)
        bias = CLOCK_BIAS_S + CLOCK_DRIFT * n
        pseudorange = distance + SPEED_OF_LIGHT * (bias - states.clock_bias_s)
        range_rate = np.einsum("ij,ij->i", los, states.velocity - velocity) + SPEED_OF_LIGHT * (
            CLOCK_DRIFT - states.clock_drift
        )
        doppler = -range_rate / L1_WAVELENGTH
        rows = [
            (int(p), float(r), float(d))
            for p, r, d in zip(prns[up], pseudorange[up], doppler[up], strict=True)
        ]
        assert len(rows) >= 6
        messages.append(_rawx(T0_SOW + n + bias, rows))
    path = tmp_path / "drive.ubx"
    path.write_bytes(subframes + b"".join(messages))
    return path


def test_velocity_command_reads_a_ubx_log_and_recovers_the_velocity(tmp_path):
    path = _log(tmp_path)
    assert sniff_format(path) == "ubx"
    out = tmp_path / "vel.csv"
    assert main(["gnss", "velocity", str(path), "--systems", "G", "-o", str(out)]) == 0
    with out.open() as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == VELOCITY_COLUMNS
    table = np.array(rows[1:], dtype=float)
    assert table.shape[0] == 5
    np.testing.assert_allclose(table[:, 1:4], np.tile(VELOCITY_ENU, (5, 1)), atol=0.01)


def test_observation_files_of_each_format_are_recognised(tmp_path):
    logger = tmp_path / "gnss_log.txt"
    logger.write_text("# Header Description:\n# Raw,utcTimeMillis,TimeNanos\n")
    gsdc = tmp_path / "device_gnss.csv"
    gsdc.write_text("MessageType,utcTimeMillis,ArrivalTimeNanosSinceGpsEpoch\n")
    rinex = tmp_path / "rover.obs"
    rinex.write_text(
        "     3.04           OBSERVATION DATA    M: MIXED            RINEX VERSION / TYPE\n"
    )
    assert [sniff_format(p) for p in (logger, gsdc, rinex)] == ["gnsslogger", "gsdc", "rinex"]
    with pytest.raises(InputError, match="no Raw records"):
        read_observation_file(logger)
    missing = tmp_path / "missing.obs"
    with pytest.raises(InputError, match=r"missing\.obs: cannot read"):
        sniff_format(missing)


def test_android_log_without_nav_is_an_error_naming_the_file(tmp_path, capsys):
    path = write_log(tmp_path, synthetic_rows())
    assert sniff_format(path) == "gnsslogger"
    code = main(["gnss", "velocity", str(path), "-o", str(tmp_path / "v.csv")])
    assert code != 0
    assert "gnss_log.txt: no satellite states: give --nav or --orbits" in capsys.readouterr().err


@pytest.mark.shared_data
def test_gsdc_file_without_nav_is_an_error_pointing_to_the_docs(tmp_path, capsys):
    """The command takes no satellite states from a GSDC file (docs/formats.md says so)."""
    path = require_shared("android_pixel7pro/device_gnss.csv")
    assert main(["gnss", "velocity", str(path), "-o", str(tmp_path / "v.csv")]) == 1
    err = capsys.readouterr().err
    assert "device_gnss.csv: no satellite states: give --nav or --orbits" in err
    assert "GSDC file's satellite states are for the library only" in err
    assert not (tmp_path / "v.csv").exists()


def test_a_smartloc_csv_is_recognised_and_read(tmp_path):
    from tests.helpers.smartloc_text import Measurement, Truth, smartloc_text

    path = tmp_path / "berlin_raw.csv"
    path.write_text(smartloc_text([(Truth(10.0), [Measurement(sv=5), Measurement(sv=9)])]))
    assert sniff_format(path) == "smartloc"
    obs, nav = read_observation_file(path)
    assert nav is None
    assert obs.select(code="D1C").satellites().tolist() == ["G05", "G09"]
    assert obs.row_fields["nlos"].tolist() == [0] * len(obs)


@pytest.mark.parametrize(
    "content", [b"# some notes\nGPSWeek;x\n", b"t,lat,lon\n1,2,3\n", b"", b"\xff\xfe junk"]
)
def test_an_unknown_format_lists_the_readable_formats_and_their_commands(tmp_path, content):
    path = tmp_path / "recording.dat"
    path.write_bytes(content)
    with pytest.raises(InputError) as caught:
        sniff_format(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: not a GNSS observation file of a format")
    for expected in (
        "RINEX 2/3/4 observations",
        "u-blox UBX",
        "Android GnssLogger",
        "GSDC device_gnss.csv",
        "smartLoc raw CSV",
        "vo-doppler import smartloc FILE -o SEQ",
        "vo-doppler import kitti-raw DRIVE -o SEQ",
        "vo-doppler import comma2k19 SEGMENT --orbits SP3 -o SEQ",
        "vo-doppler import rosbag BAG -o SEQ [--list-topics]",
        "docs/formats.md",
    ):
        assert expected in message


def test_gnss_velocity_on_an_unknown_file_exits_1_with_the_list(tmp_path, capsys):
    path = tmp_path / "notes.txt"
    path.write_text("hello\n")
    code = main(["gnss", "velocity", str(path), "-o", str(tmp_path / "v.csv")])
    assert code == 1
    err = capsys.readouterr().err
    assert "not a GNSS observation file" in err and "'hello'" in err
    assert "END OF HEADER" not in err
    assert not (tmp_path / "v.csv").exists()


def test_compressed_and_truncated_rinex_still_reach_the_rinex_reader(tmp_path):
    import gzip

    gz = tmp_path / "rover.obs.gz"
    gz.write_bytes(gzip.compress(b"junk"))
    assert sniff_format(gz) == "rinex"
    cut = tmp_path / "rover.obs"
    cut.write_text(
        "     3.04           OBSERVATION DATA    M: MIXED            RINEX VERSION / TYPE\n"
    )
    with pytest.raises(InputError, match="END OF HEADER"):
        read_observation_file(cut)
