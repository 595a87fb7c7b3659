"""Fuzz mutators, families and plausibility checks of the physical bounds (issue 30's
independent fuzz): values out of range in text tables, arrays of the wrong type, shape or length
for the npy-based comma2k19 import, UBX frames whose content is wrong but whose checksum is
valid; and, for every family of these kinds, checks that a successful read holds only values
within :mod:`vo_doppler.bounds`' bounds.

Registered by ``families.py`` with one line, after the other families::

    register_bounds(FAMILIES, register, Family, Seed, check_observations, check_navigation)

which adds the global mutation ``out_of_range_number`` (to ``mutators.TEXT_MUTATIONS``), the
families ``comma2k19-import`` (the synthetic segment of ``tests/helpers/comma2k19_segment.py``,
and the shared example segment when present, as one container file of ``.npy`` arrays) and
``ubx-frames`` (the ``ubx`` family's seed with frame-level mutations), and extends the checks of
the families registered before it (``STRICTER``).
"""

from __future__ import annotations

import io
import random
import re
import shutil
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.lib import format as npformat

from tests.conftest import shared_data_dir
from tests.fuzz.gnss_families import YAMATOGAWA, _present, make_check_ubx, ubx_seed
from tests.fuzz.mutators import TEXT_MUTATIONS
from tests.helpers.comma2k19_segment import npy_bytes, segment_arrays, write_orbits
from tests.helpers.precise_text import sp3_text
from vo_doppler.bounds import (
    ANGULAR_RATE,
    CARRIER_PHASE,
    CN0,
    DOPPLER,
    GPS_ECCENTRICITY,
    GPS_INCLINATION,
    GPS_SQRT_A,
    GPS_TIME,
    GROUND_SPEED,
    HEADING_SIGMA_DEG,
    HEIGHT,
    MAX_SATELLITES,
    MEASUREMENT_SIGMA,
    PSEUDORANGE,
    SATELLITE_CLOCK_DRIFT,
    SATELLITE_SPEED,
    SIGNAL_TRAVEL_TIME,
    SPEED,
    TIME_OFFSET,
    VELOCITY_COMPONENT,
    WHEEL_SCALE,
    YAW_RATE,
    SignalBounds,
)
from vo_doppler.errors import VoDopplerError
from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.io.ubx import checksum, read_ubx
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

# ---------------------------------------------------------------------------------------------
# Out-of-range numbers in text tables (a global text mutation)

_TOKEN = re.compile(rb"(?<![\w.+-])-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?(?![\w.])")
OUT_OF_RANGE = (
    b"-1",
    b"-5",
    b"0",
    b"-0.5",
    b"2",
    b"50",
    b"181",
    b"100.7",
    b"254",
    b"1e9",
    b"-1e9",
    b"1e20",
    b"1e30",
    b"9e18",
    b"-1e308",
    b"1e300",
    b"7000",
)
"""Values beyond some physical bound of nearly every column: negative σ and counts, a zero
scale, a longitude of 181°, a GPS satellite 254, a week after 2100, speeds of 1e9 …"""


def out_of_range_number(data: bytes, rng: random.Random) -> bytes:
    """One number of a line (integers included) replaced by a value out of a physical range."""
    lines = data.split(b"\n")
    for _ in range(20):
        k = rng.randrange(len(lines))
        found = list(_TOKEN.finditer(lines[k]))
        if found:
            match = rng.choice(found)
            new = rng.choice(OUT_OF_RANGE)
            lines[k] = lines[k][: match.start()] + new + lines[k][match.end() :]
            break
    return b"\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Arrays: a container of .npy files and mutations of one array in it

MARK = b"#npy "


def pack_arrays(arrays: list[tuple[str, bytes]]) -> bytes:
    """``#npy RELATIVE LENGTH`` lines, each followed by that many bytes of an ``.npy`` file."""
    out = []
    for relative, data in arrays:
        out.append(MARK + relative.encode() + b" " + str(len(data)).encode() + b"\n" + data)
    return b"".join(out)


def unpack_arrays(data: bytes) -> list[tuple[str, bytes]]:
    """The entries of a container; a damaged header line ends it (later arrays are missing), a
    length past the end gives the bytes that are there (a truncated file)."""
    entries, position = [], 0
    while data.startswith(MARK, position):
        end = data.find(b"\n", position)
        if end < 0:
            break
        fields = data[position + len(MARK) : end].split(b" ")
        if len(fields) != 2 or not fields[1].isdigit():
            break
        try:
            relative = fields[0].decode("ascii")
        except UnicodeDecodeError:
            break
        length = int(fields[1])
        entries.append((relative, data[end + 1 : end + 1 + length]))
        position = end + 1 + length
    return entries


def _array_mutation(change):
    """A text mutation that applies ``change(array, rng) -> bytes`` to one array of the
    container (the bytes of a loadable array, or of a deliberately broken file)."""

    def mutate(data: bytes, rng: random.Random) -> bytes:
        entries = unpack_arrays(data)
        if not entries:
            return data
        k = rng.randrange(len(entries))
        try:
            array = np.load(io.BytesIO(entries[k][1]), allow_pickle=False)
        except (ValueError, OSError, EOFError):
            return data
        entries[k] = (entries[k][0], change(array, rng))
        return pack_arrays(entries)

    mutate.__name__ = change.__name__
    return mutate


def wrong_dtype(array: np.ndarray, rng: random.Random) -> bytes:
    kind = rng.choice(("U", "c", "b", "i1", "f2", "S", "V"))
    if kind == "V":
        return npy_bytes(np.zeros(array.shape[:1], dtype=[("a", "<f8"), ("b", "<i4")]))
    return npy_bytes(array.astype(kind if kind != "S" else "S4"))


def wrong_shape(array: np.ndarray, rng: random.Random) -> bytes:
    choice = rng.randrange(4)
    if choice == 0 and array.ndim == 2:
        return npy_bytes(array[:, : rng.randrange(array.shape[1])])
    if choice == 1:
        return npy_bytes(array[..., None])
    if choice == 2:
        return npy_bytes(array.T.copy())
    return npy_bytes(array.ravel())


def wrong_length(array: np.ndarray, rng: random.Random) -> bytes:
    cut = rng.choice((1, 2, max(1, array.shape[0] // 2)))
    return npy_bytes(array[cut:] if rng.random() < 0.5 else array[:-cut])


def empty_array(array: np.ndarray, rng: random.Random) -> bytes:
    return npy_bytes(array[:0])


def nan_values(array: np.ndarray, rng: random.Random) -> bytes:
    if array.dtype.kind != "f" or not array.size:
        return npy_bytes(array)
    out = array.copy()
    for _ in range(rng.choice((1, 3, out.size))):
        out.flat[rng.randrange(out.size)] = rng.choice((np.nan, np.inf, -np.inf))
    return npy_bytes(out)


def unsorted_rows(array: np.ndarray, rng: random.Random) -> bytes:
    out = array.copy()
    if out.shape[0] > 1:
        a, b = sorted(rng.sample(range(out.shape[0]), 2))
        out[[a, b]] = out[[b, a]]
    return npy_bytes(out if rng.random() < 0.7 else out[::-1].copy())


def impossible_value(array: np.ndarray, rng: random.Random) -> bytes:
    """One entry, one column or every entry set to a value beyond some physical bound."""
    if array.dtype.kind != "f" or not array.size:
        return npy_bytes(array)
    out = array.copy()
    value = rng.choice((1e9, -1e9, 1e300, -1e300, 1e20, 0.0, -1.0, 7000.0, 9e18, 254.0, 50.0))
    where = rng.randrange(3)
    if where == 0:
        out.flat[rng.randrange(out.size)] = value
    elif where == 1 and out.ndim == 2:
        out[:, rng.randrange(out.shape[1])] = value
    else:
        out[...] = value
    return npy_bytes(out)


def huge_header(array: np.ndarray, rng: random.Random) -> bytes:
    """A header declaring terabytes (or a few rows more than the data) over the same data."""
    rows = rng.choice((10**12, 2**40 // 8, array.shape[0] + 1 if array.ndim else 2))
    shape = (rows, *array.shape[1:])
    out = io.BytesIO()
    npformat.write_array_header_1_0(
        out, {"descr": npformat.dtype_to_descr(array.dtype), "fortran_order": False, "shape": shape}
    )
    return out.getvalue() + array.tobytes()


ARRAY_MUTATIONS = {
    f"array_{change.__name__}": _array_mutation(change)
    for change in (
        wrong_dtype,
        wrong_shape,
        wrong_length,
        empty_array,
        nan_values,
        unsorted_rows,
        impossible_value,
        huge_header,
    )
}
"""Mutations of one array of a container: type, shape, length, empty, NaN, order, impossible
values, a header claiming more data than the file holds."""

# ---------------------------------------------------------------------------------------------
# The comma2k19 import family

COMMA = "comma2k19_example1"
REAL_SP3 = f"{COMMA}/Sta20124_1400_1845.sp3"
REAL_ARRAYS = (
    "global_pose/frame_times",
    "global_pose/frame_gps_times",
    "global_pose/frame_positions",
    "global_pose/frame_velocities",
    "global_pose/frame_orientations",
    "processed_log/IMU/gyro/t",
    "processed_log/IMU/gyro/value",
    "processed_log/IMU/accelerometer/t",
    "processed_log/IMU/accelerometer/value",
    "processed_log/CAN/wheel_speed/t",
    "processed_log/CAN/wheel_speed/value",
    "processed_log/GNSS/raw_gnss_ublox/t",
    "processed_log/GNSS/raw_gnss_ublox/value",
)
_ORBITS: dict[str, Path] = {}


def synthetic_segment() -> bytes:
    return pack_arrays([(k, npy_bytes(v)) for k, v in segment_arrays().items()])


REAL_SECONDS = 8.0
"""Seconds of the example segment kept (the first), so that one import stays well within the
runner's 5 s on a loaded machine."""


def real_segment() -> bytes:
    """The example segment's first ``REAL_SECONDS``: every folder's arrays cut by its own times
    (``global_pose`` by ``frame_times``)."""
    base = shared_data_dir() / COMMA
    entries = []
    for relative in REAL_ARRAYS:
        folder = relative.rsplit("/", 1)[0]
        times = "frame_times" if folder == "global_pose" else "t"
        t = np.load(base / folder / times)
        array = np.load(base / relative)
        entries.append((relative, npy_bytes(array[t < t[0] + REAL_SECONDS])))
    return pack_arrays(entries)


def _orbits(real: bool) -> Path:
    """The orbits of a seed, written once per process: the synthetic segment's, or the example
    segment's SP3 cut to the two hours around it (reading the whole day twice per case would
    take most of the runner's 5 s)."""
    if real and "real" not in _ORBITS:
        day = read_sp3(shared_data_dir() / REAL_SP3)
        start = float(
            np.load(shared_data_dir() / COMMA / "global_pose" / "frame_gps_times")[0]
            @ [SECONDS_PER_WEEK, 1.0]
        )
        near = np.abs(day.t - start) < 3600.0
        folder = Path(tempfile.mkdtemp(prefix="vo-doppler-fuzz-orbits-"))
        path = folder / "example.sp3"
        text = sp3_text(day.t[near], list(day.sat_id), day.position[near], day.clock_s[near])
        path.write_text(text)
        _ORBITS["real"] = path
    if real:
        return _ORBITS["real"]
    if "synthetic" not in _ORBITS:
        folder = Path(tempfile.mkdtemp(prefix="vo-doppler-fuzz-orbits-"))
        _ORBITS["synthetic"] = write_orbits(folder / "synthetic.sp3")
    return _ORBITS["synthetic"]


@dataclass(frozen=True)
class CommaImport:
    """What an import wrote and how ``run``'s reader took it (``refused``: its error)."""

    folder: Path
    sequence: object | None
    refused: str


def read_comma_import(path: Path) -> CommaImport:
    """Unpack the container into the segment ``<path>.d`` and import it into ``<path>.out``
    (both emptied first), then read the sequence written as ``run`` does."""
    segment, output = Path(f"{path}.d"), Path(f"{path}.out")
    for folder in (segment, output):
        shutil.rmtree(folder, ignore_errors=True)
    segment.mkdir()
    for relative, data in unpack_arrays(path.read_bytes()):
        target = (segment / relative).resolve()
        if segment.resolve() in target.parents and len(relative) < 200:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
    import_comma2k19(segment, output, _orbits(path.name.endswith(".real.c2k")))
    try:
        return CommaImport(output, read_sequence(output), "")
    except VoDopplerError as exc:
        return CommaImport(output, None, str(exc))


def _outside(name: str, bounds: SignalBounds, values) -> list[str]:
    values = np.asarray(values, dtype=float).ravel()
    if values.size and bounds.outside(values).any():
        first = values[bounds.outside(values)][0]
        return [f"{name} {first:g} outside {bounds}"]
    return []


def check_observation_values(obs, what: str) -> list[str]:
    """Every observation value within its kind's bounds (C, L, D, S) and finite."""
    bad = [] if np.isfinite(obs.value).all() else [f"{what} value not finite"]
    kinds = np.array([c[0] for c in obs.codes])[obs.code] if obs.code.size else np.array([])
    for kind, bounds in (("C", PSEUDORANGE), ("L", CARRIER_PHASE), ("D", DOPPLER), ("S", CN0)):
        bad += _outside(f"{what} {kind}", bounds, obs.value[kinds == kind])
    return bad


def check_comma_import(result: CommaImport, path: Path) -> list[str]:
    if result.refused:
        return [f"the import wrote a sequence that run refuses: {result.refused[:200]}"]
    sequence = result.sequence
    bad = check_observation_values(sequence.observations, "RINEX")
    truth = sequence.truth
    bad += _outside("truth time", GPS_TIME, truth.t)
    if not np.isfinite(truth.positions).all():
        bad.append("truth positions not finite")
    elif len(truth) > 1:
        step = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1) / np.diff(truth.t)
        bad += _outside("truth speed", SignalBounds(0.0, 2.0 * SPEED.high, "m/s"), step)
    bad += _outside("origin height", HEIGHT, [sequence.enu.height_m])
    bad += _outside("yaw rate", YAW_RATE, sequence.yaw_rate.value)
    bad += _outside("wheel speed", SPEED, sequence.wheel_speed.value)
    bad += _outside("clock offset", TIME_OFFSET, list(sequence.clock_offsets_s.values()))
    return bad


# ---------------------------------------------------------------------------------------------
# UBX frames with a valid checksum


def _frames(data: bytes) -> list[tuple[int, int]]:
    """(start, end) of every complete UBX frame."""
    found, position = [], 0
    while (start := data.find(b"\xb5\x62", position)) >= 0 and start + 8 <= len(data):
        end = start + 8 + int.from_bytes(data[start + 4 : start + 6], "little")
        if end > len(data):
            break
        found.append((start, end))
        position = end
    return found


def _reframed(data: bytes, start: int, end: int, cls_id: bytes, payload: bytes) -> bytes:
    body = cls_id + len(payload).to_bytes(2, "little") + payload
    return data[:start] + b"\xb5\x62" + body + checksum(body) + data[end:]


def _frame_mutation(change):
    def mutate(data: bytes, rng: random.Random) -> bytes:
        frames = _frames(data)
        if not frames:
            return data
        start, end = rng.choice(frames)
        payload = change(bytearray(data[start + 6 : end - 2]), data[start + 2 : start + 4], rng)
        return _reframed(data, start, end, data[start + 2 : start + 4], bytes(payload))

    mutate.__name__ = change.__name__
    return mutate


def empty_payload(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    return bytearray()


def payload_length(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    cut = rng.choice((1, 4, 16, 32, max(1, len(payload) // 2)))
    if rng.random() < 0.5:
        return payload[:-cut]
    return payload + bytes(rng.randrange(256) for _ in range(cut))


def payload_field(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    """1, 2, 4 or 8 bytes of the payload set to an extreme or random pattern."""
    if not payload:
        return payload
    width = rng.choice((1, 2, 4, 8))
    at = rng.randrange(max(1, len(payload) - width + 1))
    pattern = rng.choice((b"\xff", b"\x7f", b"\x80", b"\x00", bytes([rng.randrange(256)])))
    payload[at : at + width] = (pattern * width)[: len(payload) - at]
    return payload


def satellite_number(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    """A RXM-RAWX measurement's or RXM-SFRBX's satellite number set to any byte."""
    if kind == b"\x02\x15" and len(payload) >= 48:
        payload[16 + 32 * rng.randrange((len(payload) - 16) // 32) + 21] = rng.randrange(256)
    elif kind == b"\x02\x13" and len(payload) >= 2:
        payload[1] = rng.randrange(256)
    return payload


def pvt_velocity(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    """A NAV-PVT's velocity, ground speed or height set to a value of any size."""
    if kind == b"\x01\x07" and len(payload) >= 92:
        at = rng.choice((32, 48, 52, 56, 60))  # height, velN, velE, velD, gSpeed
        value = rng.choice((900_000_000, -900_000_000, 151_000, 2**31 - 1, -(2**31), 0))
        payload[at : at + 4] = value.to_bytes(4, "little", signed=True)
    return payload


def subframe_bit(payload: bytearray, kind: bytes, rng: random.Random) -> bytearray:
    """One bit of a RXM-SFRBX word flipped (the checksum made valid again)."""
    if kind == b"\x02\x13" and len(payload) >= 12:
        word = rng.randrange((len(payload) - 8) // 4)
        bit = rng.randrange(30)
        payload[8 + 4 * word + bit // 8] ^= 1 << (bit % 8)
    return payload


UBX_MUTATIONS = {
    f"ubx_{change.__name__}": _frame_mutation(change)
    for change in (
        empty_payload,
        payload_length,
        payload_field,
        satellite_number,
        pvt_velocity,
        subframe_bit,
    )
}


def check_ubx_bounds(recording, path: Path) -> list[str]:
    """What a u-blox receiver on a road vehicle can report, and GPS orbits."""
    bad = []
    if recording.observations is not None:
        bad += check_observation_values(recording.observations, "RXM-RAWX")
    fix = recording.solution
    bad += _outside("NAV-PVT velocity", VELOCITY_COMPONENT, fix.velocity_ned)
    bad += _outside("NAV-PVT speed", GROUND_SPEED, fix.speed)
    bad += _outside("NAV-PVT height", HEIGHT, fix.height)
    kepler = recording.navigation.kepler
    for name, bounds in (("sqrt_a", GPS_SQRT_A), ("e", GPS_ECCENTRICITY), ("i0", GPS_INCLINATION)):
        bad += _outside(f"GPS {name}", bounds, kepler.params[name][kepler.system == "G"])
    return bad


# ---------------------------------------------------------------------------------------------
# Stricter checks of the families registered before this module


def _sigma(name: str, sigma) -> list[str]:
    sigma = np.asarray(sigma, dtype=float)
    return _outside(name, MEASUREMENT_SIGMA, sigma[~np.isnan(sigma)])


def stricter_heading(table, path: Path) -> list[str]:
    bad = []
    for name in ("sigma_tc", "sigma_conv"):
        degrees = np.degrees(np.asarray(getattr(table, name), dtype=float))
        bad += _outside(name, HEADING_SIGMA_DEG, degrees[~np.isnan(degrees)])
    scale = np.asarray(table.wheel_scale, dtype=float)
    bad += _outside("wheel scale", WHEEL_SCALE, scale[~np.isnan(scale)])
    bias = np.asarray(table.gyro_bias, dtype=float)
    bad += _outside("gyro bias", YAW_RATE, bias[~np.isnan(bias)])
    bad += _outside("satellites", SignalBounds(0, MAX_SATELLITES, ""), table.n_sat_epoch)
    bad += _outside("observations", SignalBounds(0, 1e7, ""), table.n_obs_window)
    hdop = np.asarray(table.hdop_conv, dtype=float)
    bad += _outside("HDOP", SignalBounds(1e-3, 1e4, ""), hdop[~np.isnan(hdop)])
    return bad


def stricter_gsdc(recording, path: Path) -> list[str]:
    bad = check_observation_values(recording.observations, "GSDC")
    bad += _sigma("GSDC σ", recording.sigma.sigma)
    table = recording.satellites
    bad += _outside("satellite speed", SATELLITE_SPEED, np.linalg.norm(table.velocity, axis=1))
    bad += _outside("satellite clock drift", SATELLITE_CLOCK_DRIFT, table.clock_drift)
    bad += _outside("signal travel time", SIGNAL_TRAVEL_TIME, table.travel_time_s)
    return bad


def stricter_android(log, path: Path) -> list[str]:
    return check_observation_values(log.observations, "Android") + _sigma(
        "Android σ", log.sigma.sigma
    )


def stricter_oxts(record, path: Path) -> list[str]:
    fields = record.fields
    bad = _outside("OXTS altitude", HEIGHT, fields["alt"])
    bad += _outside("OXTS forward speed", SPEED, fields["vf"])
    for name in ("vn", "ve", "vl", "vu"):
        bad += _outside(f"OXTS {name}", VELOCITY_COMPONENT, fields[name])
    for name in ("wx", "wy", "wz", "wf", "wl", "wu"):
        bad += _outside(f"OXTS {name}", ANGULAR_RATE, fields[name])
    return bad


def stricter_gps(fixes, path: Path) -> list[str]:
    speed = np.asarray(getattr(fixes, "speed", np.zeros(0)), dtype=float)
    return _outside("ground speed", GROUND_SPEED, speed[~np.isnan(speed)])


def stricter_manifest(sequence, path: Path) -> list[str]:
    bad = _outside("clock offset", TIME_OFFSET, list(sequence.clock_offsets_s.values()))
    bad += _outside("yaw rate", YAW_RATE, sequence.yaw_rate.value)
    return bad + _outside("wheel speed", SPEED, sequence.wheel_speed.value)


def stricter_raw_gnss(raw, path: Path) -> list[str]:
    carrier = raw.carrier_phase[~np.isnan(raw.carrier_phase)]
    return _outside("carrier phase", CARRIER_PHASE, carrier) + _outside(
        "raw GNSS time", GPS_TIME, raw.t
    )


def stricter_series(bounds: SignalBounds, what: str):
    def check(series, path: Path) -> list[str]:
        return _outside(what, bounds, series.value)

    return check


def stricter_can(motion, path: Path) -> list[str]:
    bad = []
    if motion.yaw_rate is not None:
        bad += _outside("CAN yaw rate", YAW_RATE, motion.yaw_rate.value)
    if motion.speed is not None:
        bad += _outside("CAN speed", SPEED, motion.speed.value)
    return bad


STRICTER = {
    "heading-csv": stricter_heading,
    "gsdc": stricter_gsdc,
    "android": stricter_android,
    "kitti-oxts": stricter_oxts,
    "gps-csv-nmea": stricter_gps,
    "manifest": stricter_manifest,
    "comma-raw-gnss": stricter_raw_gnss,
    "sensor-csv": stricter_series(SPEED, "speed"),
    "gyro-csv": stricter_series(YAW_RATE, "yaw rate"),
    "can-log": stricter_can,
    "ubx": check_ubx_bounds,
}
"""Family → further check of a successful read (the physical bounds)."""


def _both(first, second):
    def check(result, path: Path) -> list[str]:
        return first(result, path) + second(result, path)

    return check


def register_bounds(
    families: dict, register, family_cls, seed_cls, check_observations, check_navigation
) -> None:
    """Add ``out_of_range_number`` to the common text mutations, register the comma2k19 import
    and UBX frame families, and extend the checks of the families already registered."""
    TEXT_MUTATIONS.setdefault("out_of_range_number", out_of_range_number)
    for name, extra in STRICTER.items():
        if name in families:
            families[name] = replace(families[name], check=_both(families[name].check, extra))

    def comma_seeds():
        seeds = [seed_cls("synthetic segment", synthetic_segment, suffix=".c2k")]
        if _present(REAL_SP3, *(f"{COMMA}/{r}" for r in REAL_ARRAYS)):
            seeds.append(seed_cls("comma2k19 example segment", real_segment, suffix=".real.c2k"))
        return seeds

    register(
        family_cls(
            "comma2k19-import",
            comma_seeds,
            read_comma_import,
            check_comma_import,
            mutations=dict(ARRAY_MUTATIONS),
        )
    )
    if _present(f"{YAMATOGAWA}/yamatogawa_rover.obs", f"{YAMATOGAWA}/brdc0060.10n"):
        check_ubx = make_check_ubx(check_observations, check_navigation)
        register(
            family_cls(
                "ubx-frames",
                lambda: [seed_cls("yamatogawa.ubx", ubx_seed, suffix=".ubx")],
                read_ubx,
                _both(check_ubx, check_ubx_bounds),
                mutations=dict(UBX_MUTATIONS),
            )
        )
