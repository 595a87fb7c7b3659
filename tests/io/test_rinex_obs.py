"""RINEX observation reader on synthetic files: exact values, versions, compression, events."""

from __future__ import annotations

import gzip

import hatanaka
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.helpers.rinex_text import field, rinex2_epoch, rinex2_header, rinex3_epoch, rinex3_header
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import PRN_RANGE
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.gpstime import calendar_to_gps_seconds

T0 = float(calendar_to_gps_seconds(2024, 6, 24, 8, 20, 0))
TYPES = {"G": ["C1C", "L1C", "D1C", "S1C"], "R": ["C1C", "D1C"], "E": ["C1C", "D1C", "S1C", "C5Q"]}

values = st.one_of(
    st.none(),
    st.integers(min_value=-99_999_999_999, max_value=999_999_999_999).map(lambda k: k / 1000),
)
indicators = st.one_of(st.none(), st.integers(0, 9))


def observation_rows(obs) -> list[tuple]:
    """Every observation as (time, satellite, code, value, LLI, SSI), sorted."""
    return sorted(
        zip(
            obs.time.tolist(),
            obs.satellites().tolist(),
            [obs.codes[c] for c in obs.code],
            obs.value.tolist(),
            obs.lli.tolist(),
            obs.ssi.tolist(),
            strict=True,
        )
    )


def satellite_ids(systems):
    """(system, number) pairs with numbers valid for the system (RINEX 3.05 sec. 3.5)."""
    return st.sampled_from(systems).flatmap(
        lambda s: st.tuples(st.just(s), st.integers(*PRN_RANGE[s]))
    )


@st.composite
def epochs(draw):
    satellites = draw(
        st.lists(
            satellite_ids(sorted(TYPES)),
            min_size=1,
            max_size=15,
            unique=True,
        )
    )
    records = []
    for system, prn in satellites:
        fields = [(draw(values), draw(indicators), draw(indicators)) for _ in TYPES[system]]
        records.append((f"{system}{prn:02d}", fields))
    return records


@pytest.mark.slow
@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(epochs(), min_size=1, max_size=4))
def test_rinex3_round_trip(tmp_path, written):
    text = rinex3_header(TYPES)
    expected = []
    for k, records in enumerate(written):
        text += rinex3_epoch(
            f"2024 06 24 08 20 {k:2d}.0000000",
            [(sat, [field(*f) for f in fields]) for sat, fields in records],
        )
        for sat, fields in records:
            for code, (value, lli, ssi) in zip(TYPES[sat[0]], fields, strict=True):
                if value is not None:
                    expected.append(
                        (
                            T0 + k,
                            sat,
                            code,
                            value,
                            -1 if lli is None else lli,
                            -1 if ssi is None else ssi,
                        )
                    )
    path = tmp_path / "random.24o"
    path.write_text(text)
    if not expected:
        with pytest.raises(InputError, match="no observation could be read"):
            read_obs(path)
        return
    obs = read_obs(path)
    assert observation_rows(obs) == sorted(expected)
    assert obs.problems == ()
    np.testing.assert_array_equal(obs.epoch_time, T0 + np.arange(len(written)))


def _rinex2_file(n_sats: int = 14) -> tuple[str, list[str], dict]:
    types = ["C1", "L1", "D1", "S1", "P2", "L2", "D2"]
    records, expected = [], {}
    for k in range(n_sats):
        values = [20_000_000.0 + k, -1234.567 - k, 2000.25 * (k % 3 - 1), 40.0 + k, None, 7.5, -k]
        fields = [field(v, 1 if i == 1 else None, 7) for i, v in enumerate(values)]
        records.append((f"G{k + 1:2d}", fields))
        expected[f"G{k + 1:02d}"] = values
    text = rinex2_header(types) + rinex2_epoch(" 10  1  6  5 57  3.0000000", records)
    text += rinex2_epoch(" 10  1  6  5 57  4.0000000", records[:3])
    return text, types, expected


def test_rinex2_long_epoch_and_continuation_lines(tmp_path):
    text, types, expected = _rinex2_file()
    path = tmp_path / "walk.10o"
    path.write_text(text)
    obs = read_obs(path)
    t0 = float(calendar_to_gps_seconds(2010, 1, 6, 5, 57, 3.0))
    np.testing.assert_array_equal(obs.epoch_time, [t0, t0 + 1])
    first = obs.time == t0
    sats = obs.satellites()
    for sat, vals in expected.items():
        for code, value in zip(types, vals, strict=True):
            rows = first & (sats == sat) & obs.mask(code=code)
            assert rows.sum() == (value is not None)
            if value is not None:
                assert obs.value[rows][0] == value
    assert np.all(obs.lli[obs.mask(code="L1")] == 1)
    assert np.all(obs.lli[obs.mask(code="C1")] == -1)
    assert np.all(obs.ssi == 7)
    assert (obs.time == t0 + 1).sum() == 3 * 6


def test_gzip_and_hatanaka_equal_plain(tmp_path):
    text, _, _ = _rinex2_file()
    plain = tmp_path / "walk.10o"
    plain.write_text(text)
    (tmp_path / "walk.10o.gz").write_bytes(gzip.compress(text.encode()))
    (tmp_path / "walk.10d").write_bytes(hatanaka.compress(text.encode(), compression="none"))
    reference = read_obs(plain)
    for name in ("walk.10o.gz", "walk.10d"):
        other = read_obs(tmp_path / name)
        np.testing.assert_array_equal(other.value, reference.value)
        np.testing.assert_array_equal(other.lli, reference.lli)
        np.testing.assert_array_equal(other.time, reference.time)


def test_rinex3_event_flags(tmp_path):
    g = [("G05", [field(1.0), field(2.0), field(3.0), field(4.0)])]
    text = rinex3_header({"G": ["C1C", "L1C", "D1C", "S1C"]})
    text += rinex3_epoch("2024 06 24 08 20  0.0000000", g)
    text += "> 2024 06 24 08 20  0.5000000  2  1\nCOMMENT LINE THAT STARTS WITH G\n"
    text += "> 2024 06 24 08 20  1.0000000  1  1\n" + "G05" + field(9.0) + "\n"
    new_types = "G    2 D1C C1C" + " " * 46 + "SYS / # / OBS TYPES \n"
    text += ">" + " " * 30 + "4  1\n" + new_types
    text += rinex3_epoch("2024 06 24 08 20  2.0000000", [("G05", [field(5.0), field(6.0)])])
    text += rinex3_epoch("2024 06 24 08 20  3.0000000", [("G05", [field(7.0)])], flag=6)
    path = tmp_path / "events.24o"
    path.write_text(text)
    obs = read_obs(path)
    np.testing.assert_array_equal(obs.epoch_time, T0 + np.array([0.0, 1.0, 2.0]))
    np.testing.assert_array_equal(obs.epoch_flag, [0, 1, 0])
    last = obs.time == T0 + 2
    assert obs.value[last & obs.mask(code="D1C")].tolist() == [5.0]
    assert obs.value[last & obs.mask(code="C1C")].tolist() == [6.0]
    assert obs.value[obs.time == T0 + 1].tolist() == [9.0]
    assert obs.problems == ()


def test_header_fields(tmp_path):
    text = rinex3_header({"G": ["C1C"]}, time_system="GPS")
    path = tmp_path / "h.24o"
    path.write_text(text + rinex3_epoch("2024 06 24 08 20  0.0000000", [("G01", [field(1.0)])]))
    header = read_obs(path).header
    assert header.version == 3.04
    assert header.interval == 1.0
    assert header.obs_types == {"G": ("C1C",)}
    np.testing.assert_array_equal(
        header.approx_position, [-3817680.9841, 3562840.0688, 3650158.4543]
    )


def test_glonass_time_system_is_converted_to_gps(tmp_path):
    text = rinex3_header({"R": ["C1C"]}, time_system="GLO")
    path = tmp_path / "glo.24o"
    path.write_text(text + rinex3_epoch("2024 06 24 08 20  0.0000000", [("R01", [field(1.0)])]))
    assert read_obs(path).epoch_time[0] == T0 + 18.0


@pytest.mark.parametrize(
    ("version", "time_system", "allowed"),
    [("2.10", "UTC", "GPS, GLO"), ("2.10", "GAL", "GPS, GLO"), ("2.11", "BDT", "GPS, GLO, GAL")],
)
def test_a_time_system_the_rinex2_version_lacks_is_read_as_gps_and_named(
    tmp_path, version, time_system, allowed
):
    header = rinex2_header(["C1"]).replace("     2.11 ", f"     {version} ", 1)
    header = header.replace("3.0000000     GPS", f"3.0000000     {time_system}")
    path = tmp_path / "utc.10o"
    path.write_text(header + rinex2_epoch(" 10  1  6  5 57  3.0000000", [("G05", [field(2e7)])]))
    obs = read_obs(path)
    assert obs.header.time_system == "GPS"
    assert obs.epoch_time[0] == calendar_to_gps_seconds(2010, 1, 6, 5, 57, 3.0)
    assert obs.problems == (
        f"{path}:3: TIME OF FIRST OBS time system {time_system!r} is not one of RINEX "
        f"{version}'s ({allowed}): the epochs are read as GPS time (UTC epochs would be the "
        "leap seconds behind)",
    )


def test_the_time_systems_each_version_defines_raise_no_problem(tmp_path):
    header = rinex2_header(["C1"], system="M").replace("3.0000000     GPS", "3.0000000     GAL")
    path = tmp_path / "gal.10o"
    path.write_text(header + rinex2_epoch(" 10  1  6  5 57  3.0000000", [("E05", [field(2e7)])]))
    assert read_obs(path).problems == ()
    text = rinex3_header({"C": ["C2I"]}, time_system="BDT")
    path = tmp_path / "bdt.24o"
    path.write_text(text + rinex3_epoch("2024 06 24 08 20  0.0000000", [("C11", [field(1.0)])]))
    obs = read_obs(path)
    assert obs.problems == () and obs.epoch_time[0] == T0 + 14.0
    path.write_text(
        rinex3_header({"G": ["C1C"]}, time_system="UTC")
        + rinex3_epoch("2024 06 24 08 20  0.0000000", [("G01", [field(1.0)])])
    )
    (problem,) = read_obs(path).problems
    assert "time system 'UTC' is not one of RINEX 3.04's (GPS, GLO, GAL, QZS, BDT, IRN)" in problem


def test_rinex2_mixed_file_events_and_blank_system_letter(tmp_path):
    types = ["C1", "D1"]
    g = [("  5", [field(2.0e7), field(-100.0)]), ("R 3", [field(2.1e7), field(200.0)])]
    text = rinex2_header(types, system="M")
    text += rinex2_epoch(" 10  1  6  5 57  3.0000000", g)
    # flag 4: header records inside the body change the observation types
    new_types = "     3    D1    C1    S1" + " " * 36 + "# / TYPES OF OBSERV \n"
    text += " " * 28 + "4  2\n" + new_types + " " * 60 + "COMMENT             \n"
    text += rinex2_epoch(
        " 10  1  6  5 57  4.0000000", [("G05", [field(-101.0), field(2.0e7 + 1), field(45.0)])]
    )
    text += rinex2_epoch(" 10  1  6  5 57  5.0000000", [("G05", [field(1.0)] * 3)], flag=6)
    path = tmp_path / "mixed.10o"
    path.write_text(text)
    obs = read_obs(path)
    assert obs.problems == ()
    t0 = float(calendar_to_gps_seconds(2010, 1, 6, 5, 57, 3.0))
    np.testing.assert_array_equal(obs.epoch_time, [t0, t0 + 1])
    assert obs.satellites()[obs.time == t0].tolist() == ["G05", "G05", "R03", "R03"]
    second = obs.time == t0 + 1
    assert obs.value[second & obs.mask(code="D1")].tolist() == [-101.0]
    assert obs.value[second & obs.mask(code="S1")].tolist() == [45.0]


def test_hatanaka_rinex3_real_file_equals_plain(tmp_path):
    from tests.conftest import require_shared

    source = require_shared("septentrio_static/rover.obs")
    crx = tmp_path / "rover.crx.gz"
    crx.write_bytes(hatanaka.compress(source.read_bytes(), compression="gz"))
    plain, compressed = read_obs(source), read_obs(crx)
    np.testing.assert_array_equal(compressed.value, plain.value)
    np.testing.assert_array_equal(compressed.ssi, plain.ssi)
    np.testing.assert_array_equal(compressed.lli, plain.lli)
    assert compressed.codes == plain.codes


def test_matrix_helper(tmp_path):
    text = rinex3_header(TYPES)
    text += rinex3_epoch("2024 06 24 08 20  0.0000000", [("G05", [field(1.0)] * 4)])
    both = [("G05", [field(2.0)] * 4), ("E04", [field(3.0)] * 4)]
    text += rinex3_epoch("2024 06 24 08 20  1.0000000", both)
    path = tmp_path / "m.24o"
    path.write_text(text)
    names, values = read_obs(path).matrix("C1C")
    assert names.tolist() == ["E04", "G05"]
    np.testing.assert_array_equal(values, [[np.nan, 1.0], [3.0, 2.0]])
    names, _ = read_obs(path).matrix("C1C", system="G")
    assert names.tolist() == ["G05"]


TYPES2 = ["C1", "L1", "D1", "S1", "P2", "L2", "D2"]


@st.composite
def epochs2(draw):
    satellites = draw(
        st.lists(
            satellite_ids("GR"),
            min_size=1,
            max_size=26,
            unique=True,
        )
    )
    return [
        (f"{s}{p:2d}", [(draw(values), draw(indicators), draw(indicators)) for _ in TYPES2])
        for s, p in satellites
    ]


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(epochs2(), min_size=1, max_size=3))
def test_rinex2_round_trip(tmp_path, written):
    text = rinex2_header(TYPES2, system="M")
    expected = []
    t0 = float(calendar_to_gps_seconds(2010, 1, 6, 5, 57, 0.0))
    for k, records in enumerate(written):
        text += rinex2_epoch(
            f" 10  1  6  5 57 {k:2d}.0000000",
            [(sat, [field(*f) for f in fields]) for sat, fields in records],
        )
        for sat, fields in records:
            for code, (value, lli, ssi) in zip(TYPES2, fields, strict=True):
                if value is not None:
                    flags = (-1 if lli is None else lli, -1 if ssi is None else ssi)
                    expected.append((t0 + k, sat.replace(" ", "0"), code, value, *flags))
    path = tmp_path / "random.10o"
    path.write_text(text)
    if not expected:
        with pytest.raises(InputError, match="no observation could be read"):
            read_obs(path)
        return
    obs = read_obs(path)
    assert observation_rows(obs) == sorted(expected)
    assert obs.problems == ()


GLONASS_CHANNELS = {1: 1, 2: -4, 3: 5, 4: 6, 5: 1, 6: -4, 7: 5, 8: 6, 9: -2, 10: -7}


def _with_slot_lines(tmp_path, slot_lines: list[str]):
    """A RINEX 3 file whose header carries these 'GLONASS SLOT / FRQ #' lines (content only,
    the label appended after column 60 or, for longer content, right after it)."""
    header = rinex3_header({"R": ["C1C"]})
    block = "".join(f"{content:<60}GLONASS SLOT / FRQ #\n" for content in slot_lines)
    path = tmp_path / "slots.24o"
    path.write_text(
        header.replace("     1.000", block + "     1.000", 1)
        + rinex3_epoch("2024 06 24 08 20  0.0000000", [("R01", [field(2.0e7)])])
    )
    return read_obs(path)


@pytest.mark.parametrize(
    "slot_lines",
    [
        # RINEX 3.05 Table A2: I3,1X,8(A1,I2.2,1X,I2,1X), continuation with the count blank
        [" 10 R01  1 R02 -4 R03  5 R04  6 R05  1 R06 -4 R07  5 R08  6", "    R09 -2 R10 -7"],
        # one blank between slot and channel: every fixed 7-column chunk after the first shifts
        [" 10 R01 1 R02 -4 R03 5 R04 6 R05 1 R06 -4 R07 5 R08 6 R09 -2", "    R10 -7"],
        # all ten pairs on one line, past column 60 (the label pushed right)
        [" 10 R01  1 R02 -4 R03  5 R04  6 R05  1 R06 -4 R07  5 R08  6 R09 -2 R10 -7"],
        # no count, fewer pairs per line, slots without a leading zero, explicit + signs
        ["R1 +1 R2 -4 R3 +5", "R4 +6 R5 +1 R6 -4 R7 +5", "R8 +6  R9 -2  R10 -7"],
    ],
)
def test_glonass_slot_line_variants_are_read(tmp_path, slot_lines):
    """The 'GLONASS SLOT / FRQ #' variants real writers produce are read as pairs of tokens; a
    GSDC Pixel5 file's gave six 'unreadable' warnings and no GLONASS channel."""
    obs = _with_slot_lines(tmp_path, slot_lines)
    assert obs.header.glonass_channels == GLONASS_CHANNELS
    assert obs.problems == ()


def test_glonass_slot_line_unreadable_text_named_once_per_line(tmp_path):
    obs = _with_slot_lines(tmp_path, ["  4 R01  1 R02 -4 R40  1 Rxx  9 R05  1 R06 12"])
    assert obs.header.glonass_channels == {1: 1, 2: -4, 5: 1}
    assert len(obs.problems) == 1
    assert "'R40 1', 'Rxx  9', 'R06 12' ignored" in obs.problems[0]
    assert obs.problems[0].split(":")[1] == "4"  # the record's line, after three header lines


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    channels=st.dictionaries(st.integers(1, 27), st.integers(-7, 6), min_size=1, max_size=24),
    per_line=st.integers(1, 12),
    gap=st.sampled_from([" ", "  ", "   "]),
    padded=st.booleans(),
    count=st.booleans(),
)
def test_glonass_slot_pairs_read_whatever_the_layout(
    tmp_path, channels, per_line, gap, padded, count
):
    """Any spacing, any number of pairs per line, with or without the count: the same map."""
    pairs = [
        f"R{slot:02d}{gap}{channel:2d}" if padded else f"R{slot}{gap}{channel}"
        for slot, channel in channels.items()
    ]
    lines = [" ".join(pairs[k : k + per_line]) for k in range(0, len(pairs), per_line)]
    lines = [
        (f"{len(channels):3d} " if count and k == 0 else "    ") + line
        for k, line in enumerate(lines)
    ]
    obs = _with_slot_lines(tmp_path, lines)
    assert obs.header.glonass_channels == channels
    assert obs.problems == ()
