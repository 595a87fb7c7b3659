"""Reader families for the fuzz runner: seed files, how they are stored, a read function and the
invariants a successful read must satisfy.

A family is registered with :func:`register`; other reader families (CAN, CSV, manifest) plug in
the same way: seed files (``Seed``), a ``read(path)`` function, a ``check(result, path)`` that
lists impossible values, and optionally ``same_content(result, original)`` for mutations that may
only lose content (see ``mutators.SHRINKING``).
"""

from __future__ import annotations

import gzip
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import hatanaka
import numpy as np

from tests.conftest import REPO_ROOT, shared_data_dir
from tests.fuzz.bound_families import register_bounds
from tests.fuzz.gnss_families import register_gnss
from tests.fuzz.import_families import register_imports
from tests.fuzz.mutators import SHRINKING
from tests.fuzz.rosbag_families import register_rosbag
from tests.fuzz.sfrbx_families import register_sfrbx
from tests.helpers.rinex_text import as_rinex4
from tests.io.fuzz_families import register_all
from vo_doppler.io.rinex_common import FIRST_YEAR, LAST_YEAR, PRN_RANGE
from vo_doppler.io.rinex_nav import ESSENTIAL, PLAUSIBLE, read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.gpstime import calendar_to_gps_seconds
from vo_doppler.model.navigation import Navigation, NavRecords
from vo_doppler.model.observations import Observations

CUT_END = frozenset({"truncate"})


def stored_as_is(data: bytes) -> bytes:
    return data


@dataclass(frozen=True)
class Seed:
    """One unmutated input: its plain content, how it is stored on disk and the file suffix."""

    name: str
    load: Callable[[], bytes]
    pack: Callable[[bytes], bytes] = stored_as_is
    suffix: str = ""
    shrinking: frozenset[str] = SHRINKING
    """Text mutations after which every value read must equal the unmutated file's."""


@dataclass(frozen=True)
class Family:
    name: str
    seeds: Callable[[], list[Seed]]
    read: Callable[[Path], object]
    check: Callable[[object, Path], list[str]]
    same_content: Callable[[object, object], list[str]] | None = None
    notes: dict[str, str] = field(default_factory=dict)
    mutations: dict[str, Callable] = field(default_factory=dict)
    """Text mutations of this family's format alone (e.g. of arrays in a container), drawn
    with the common ones."""


FAMILIES: dict[str, Family] = {}


def register(family: Family) -> Family:
    FAMILIES[family.name] = family
    return family


def _file(path: Path) -> Callable[[], bytes]:
    return path.read_bytes


def _gz(data: bytes) -> bytes:
    return gzip.compress(data, mtime=0)


def _crx(load: Callable[[], bytes]) -> Callable[[], bytes]:
    return lambda: hatanaka.rnx2crx(load())


SAMPLE_GNSS = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "gnss"
OBS_FILES = (
    "septentrio_static/rover.obs",
    "yamatogawa_ublox_walk/yamatogawa_rover.obs",
)
NAV_FILES = (
    "septentrio_static/base.nav",
    "yamatogawa_ublox_walk/brdc0060.10n",
    "yamatogawa_ublox_walk/yamatogawa_rover.nav",
)


def _existing(relatives: tuple[str, ...], extra: Path) -> list[Path]:
    paths = [shared_data_dir() / r for r in relatives]
    return [p for p in paths if p.is_file()] + [extra]


def obs_seeds() -> list[Seed]:
    """Observation files as plain text, gzip, Hatanaka and Hatanaka + gzip, and the sample's
    file relabelled RINEX 4.

    Text mutations of the Hatanaka seeds change the Compact RINEX text. Its values are
    differences from the epochs before, so a lost line inside it shifts later values without
    any sign in the text (only a cut end is checked against the original there).
    """
    seeds = []
    for path in _existing(OBS_FILES, SAMPLE_GNSS / "rover.obs"):
        load = _file(path)
        seeds += [
            Seed(path.name, load, suffix=".obs"),
            Seed(path.name + ".gz", load, _gz, ".obs.gz"),
            Seed(path.stem + ".crx", _crx(load), suffix=".crx", shrinking=CUT_END),
            Seed(path.stem + ".crx.gz", _crx(load), _gz, ".crx.gz", shrinking=CUT_END),
        ]
    sample = SAMPLE_GNSS / "rover.obs"
    return [
        Seed("rover.obs as RINEX 4", lambda: as_rinex4_obs(sample.read_bytes()), suffix=".rnx"),
        *seeds,
    ]


def as_rinex4_obs(v3: bytes) -> bytes:
    """A RINEX 3 observation file relabelled 4.01: the epoch and record layout is unchanged
    (RINEX 4.01 sec. 5.2), the version number is what the reader dispatches on."""
    first, _, rest = v3.partition(b"\n")
    return b"     4.01" + first[9:] + b"\n" + rest


def nav_seeds() -> list[Seed]:
    """Navigation files as plain text and gzip, plus a RINEX 4 rewrite of the Septentrio file."""
    seeds = []
    for path in _existing(NAV_FILES, SAMPLE_GNSS / "brdc.nav"):
        load = _file(path)
        seeds += [Seed(path.name, load, suffix=".nav"), Seed(path.name + ".gz", load, _gz, ".gz")]
    v3 = shared_data_dir() / NAV_FILES[0]
    if v3.is_file():
        seeds.append(Seed("base.nav as RINEX 4", lambda: as_rinex4(v3.read_bytes()), suffix=".rnx"))
    return seeds


GPS_SECONDS_RANGE = (
    float(calendar_to_gps_seconds(FIRST_YEAR, 1, 1, 0, 0, 0.0)) - 86400.0,
    float(calendar_to_gps_seconds(LAST_YEAR + 1, 1, 1, 0, 0, 0.0)) + 86400.0,
)


def _times_ok(name: str, t: np.ndarray) -> list[str]:
    if t.size and not np.isfinite(t).all():
        return [f"{name} not finite"]
    if t.size and (t.min() < GPS_SECONDS_RANGE[0] or t.max() > GPS_SECONDS_RANGE[1]):
        return [f"{name} outside {FIRST_YEAR}–{LAST_YEAR}"]
    return []


def _prn_ok(name: str, system: np.ndarray, prn: np.ndarray) -> list[str]:
    for letter in np.unique(system):
        low, high = PRN_RANGE.get(str(letter), (0, -1))
        numbers = prn[system == letter]
        if numbers.size and (numbers.min() < low or numbers.max() > high):
            return [f"{name}: {letter} number outside {low}–{high}"]
    return []


def check_observations(obs: Observations, path: Path) -> list[str]:
    """Impossible values in a successfully read observation file."""
    bad = _times_ok("epoch times", obs.epoch_time)
    if obs.epoch_time.size > 1 and not (np.diff(obs.epoch_time) > 0).all():
        bad.append("epoch times not strictly increasing")
    if not np.isin(obs.time, obs.epoch_time).all():
        bad.append("observation time not an epoch time")
    if not np.isin(obs.epoch_flag, (0, 1)).all():
        bad.append("data epoch flag other than 0/1")
    bad += _prn_ok("observations", obs.system, obs.prn)
    if not np.isfinite(obs.value).all():
        bad.append("value not finite")
    for name in ("lli", "ssi"):
        flags = getattr(obs, name)
        if flags.size and (flags.min() < -1 or flags.max() > 9):
            bad.append(f"{name} outside −1…9")
    if obs.code.size and (obs.code.min() < 0 or obs.code.max() >= len(obs.codes)):
        bad.append("code index outside the code list")
    if obs.time.size:
        keys = np.stack([obs.time, obs.prn, obs.code, [ord(s) for s in obs.system]], axis=1)
        if np.unique(keys, axis=0).shape[0] != keys.shape[0]:
            bad.append("an observation appears twice")
    position = obs.header.approx_position
    if position is not None and not (
        np.isfinite(position).all() and 6.0e6 < np.linalg.norm(position) < 7.0e6
    ):
        bad.append("approximate position not near the Earth's surface")
    channels = obs.header.glonass_channels
    if any(not (-7 <= k <= 6 and 1 <= s <= PRN_RANGE["R"][1]) for s, k in channels.items()):
        bad.append("GLONASS slot or channel out of range")
    bad += [f"problem does not name the file: {p!r}" for p in obs.problems if str(path) not in p]
    return bad


def _check_records(name: str, records: NavRecords) -> list[str]:
    bad = _times_ok(f"{name} toc", records.toc) + _prn_ok(name, records.system, records.prn)
    for key, values in records.params.items():
        if np.isinf(values).any():
            bad.append(f"{name} {key} infinite")
        if key in ESSENTIAL and not np.isfinite(values).all():
            bad.append(f"{name} {key} missing")
        if key in PLAUSIBLE and values.size:
            low, high = PLAUSIBLE[key]
            if values.min() < low or values.max() > high:
                bad.append(f"{name} {key} outside {low}–{high}")
    return bad


def check_navigation(nav: Navigation, path: Path) -> list[str]:
    """Impossible values in a successfully read navigation file."""
    bad = _check_records("kepler", nav.kepler) + _check_records("glonass", nav.glonass)
    if len(nav.kepler):
        bad += _times_ok("toe", nav.kepler["toe"])
    if len(nav.glonass):
        radius = np.linalg.norm(
            np.stack([nav.glonass["x"], nav.glonass["y"], nav.glonass["z"]]), axis=0
        )
        if radius.min() < 1.9e7 or radius.max() > 3.2e7:
            bad.append("GLONASS orbit radius outside 19,000–32,000 km")
    if nav.klobuchar is not None and not np.isfinite(nav.klobuchar).all():
        bad.append("Klobuchar coefficients not finite")
    if nav.leap_seconds is not None and not 0 <= nav.leap_seconds < 100:
        bad.append("leap seconds outside 0–99")
    bad += [f"problem does not name the file: {p!r}" for p in nav.problems if str(path) not in p]
    return bad


def _keys(obs: Observations):
    return zip(obs.time.tolist(), obs.satellites().tolist(), obs.code.tolist(), strict=True)


def same_observations(obs: Observations, original: Observations) -> list[str]:
    """Every value read from a file that only lost content equals the original's value."""
    index = {
        key: value
        for key, value in zip(
            _keys(original),
            original.value.tolist(),
            strict=True,
        )
    }
    codes = {
        c: original.codes.index(name) for c, name in enumerate(obs.codes) if name in original.codes
    }
    for key, value in zip(_keys(obs), obs.value.tolist(), strict=True):
        original_key = (key[0], key[1], codes.get(key[2], -1))
        if index.get(original_key) != value:
            return [f"value {value} of {key} is not the original's {index.get(original_key)}"]
    return []


def same_navigation(nav: Navigation, original: Navigation) -> list[str]:
    """Every record read from a file that only lost content equals an original record (a field
    left blank by the cut, NaN, is missing, not wrong: a last line cut after its first number)."""
    for name in ("kepler", "glonass"):
        ours, theirs = getattr(nav, name), getattr(original, name)
        names = sorted(theirs.params)
        table: dict[tuple, list[np.ndarray]] = {}
        for r in range(len(theirs)):
            key = (str(theirs.system[r]), int(theirs.prn[r]), float(theirs.toc[r]))
            table.setdefault(key, []).append(np.array([theirs.params[k][r] for k in names]))
        for r in range(len(ours)):
            key = (str(ours.system[r]), int(ours.prn[r]), float(ours.toc[r]))
            row = np.array([ours.params[k][r] for k in names])
            read = ~np.isnan(row)
            if not any(np.array_equal(row[read], other[read]) for other in table.get(key, [])):
                return [f"{name} record {key} differs from every original record"]
    return []


register(
    Family(
        "rinex-obs",
        obs_seeds,
        read_obs,
        check_observations,
        same_observations,
        {"versions": "2.10 (yamatogawa), 3.04 (septentrio, sample sequence)"},
    )
)
register(
    Family(
        "rinex-nav",
        nav_seeds,
        read_nav,
        check_navigation,
        same_navigation,
        {"versions": "2 (brdc, yamatogawa), 3.04 (septentrio, sample sequence), 4.01 rewrite"},
    )
)

register_all(register, Family, Seed)  # CAN, DBC, CSV, NMEA, trajectory, calibration, manifest
register_gnss(register, Family, Seed, check_observations, check_navigation)  # SP3 … raw_gnss
register_imports(register, Family, Seed, check_observations, same_observations)  # smartLoc …
register_rosbag(register, Family, Seed, check_observations)  # ROS 1 .bag, ROS 2 .mcap/.db3
register_bounds(FAMILIES, register, Family, Seed, check_observations, check_navigation)
register_sfrbx(register, Family, Seed, check_observations, check_navigation)  # Galileo, BeiDou
