"""Ground truth for scoring GNSS outputs (``vo-doppler eval gnss``), in three kinds of file:

* **TUM** (``t x y z qx qy qz qw``): positions in the ENU frame of an origin given beside it
  (``--origin``, or a ``sequence.yaml``'s ``origin``); the orientation is not used (it may be a
  camera's), the course comes from the positions.
* **lat/lon CSV**: without a header, five columns GPS week, GPS seconds of week, latitude (°),
  longitude (°), ellipsoidal height (m) (the PolyU UrbanNav / GraphGNSSLib ground truth); or
  with a header naming ``gps_time_s`` (GPS seconds since 1980-01-06), ``lat_deg``, ``lon_deg``,
  ``height_m`` (``pos.csv``'s names; ``latitude_deg``, ``longitude_deg``, ``h_m``,
  ``altitude_m`` also read) and optionally ``course_deg`` or ``heading_deg`` (clockwise from
  north).
* **GSDC** ``ground_truth.csv`` (Google Smartphone Decimeter Challenge): ``LatitudeDegrees``,
  ``LongitudeDegrees``, ``AltitudeMeters``, ``UnixTimeMillis`` (UTC, leap seconds added here)
  and, where filled, ``BearingDegrees``: the file's own heading.

Positions of the CSV kinds are put in the ENU frame of the origin when one is given, else of
their first row. Times must increase strictly; every unusable row names its line.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

import numpy as np

from vo_doppler.choices import checked
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.io.sequence import Manifest, read_manifest
from vo_doppler.io.textfile import read_text
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, unix_to_gps_seconds
from vo_doppler.model.ground_truth import GroundTruth


class TruthFormat(StrEnum):
    """The ``fmt`` of :func:`read_ground_truth` (``eval gnss --truth-format``)."""

    AUTO = "auto"
    """By :data:`AUTO_TRUTH_RULE`."""
    TUM = "tum"
    LATLON = "latlon"
    GSDC = "gsdc"


AUTO_TRUTH_RULE = (
    "by the first line: a GSDC header (UnixTimeMillis), a header with gps_time_s (lat/lon "
    "CSV), or a data row of 8 fields (TUM) or 5 (GPS week, seconds of week, lat, lon, h)"
)
LATITUDE_NAMES = ("lat_deg", "latitude_deg")
LONGITUDE_NAMES = ("lon_deg", "longitude_deg")
HEIGHT_NAMES = ("height_m", "h_m", "altitude_m")
COURSE_NAMES = ("course_deg", "heading_deg")
GSDC_COLUMNS = ("LatitudeDegrees", "LongitudeDegrees", "AltitudeMeters", "UnixTimeMillis")
HEIGHT_RANGE_M = (-1.0e3, 1.0e4)
"""Ellipsoidal heights a road can have (m): beyond them the column is not a height."""
MAX_GPS_WEEK = 1.0e5
_SEPARATORS = re.compile(r"[,\s]+")


@dataclass(frozen=True)
class HeadedColumns:
    """A headed CSV's numeric columns by name (NaN where a field is blank) and the file line of
    each row."""

    columns: dict[str, np.ndarray]
    line: np.ndarray

    def first(self, names: tuple[str, ...]) -> np.ndarray | None:
        """The first of ``names`` the file has, or None."""
        return next((self.columns[n] for n in names if n in self.columns), None)


def headed_columns(
    text: str, path: Path, what: str, wanted: tuple[str, ...], required: tuple[str, ...]
) -> HeadedColumns:
    """The ``wanted`` columns of a CSV whose first line is its header, as floats. A missing
    ``required`` column, a row with another number of fields or a field that is not a number
    raises :class:`InputError` naming the line; blank fields are NaN."""
    try:
        table = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise InputError(f"cannot read the {what} as CSV: {exc}", path) from exc
    numbered = [(n, row) for n, row in enumerate(table, start=1) if any(f.strip() for f in row)]
    if not numbered:
        raise InputError(f"the {what} is empty", path)
    header = [name.strip() for name in numbered[0][1]]
    missing = [name for name in required if name not in header]
    if missing:
        raise InputError(f"the {what} has no column {missing[0]}", path, numbered[0][0])
    present = [name for name in wanted if name in header]
    index = [header.index(name) for name in present]
    values = np.full((len(numbered) - 1, len(present)), np.nan)
    for k, (number, row) in enumerate(numbered[1:]):
        if len(row) != len(header):
            raise InputError(f"{len(row)} fields for {len(header)} columns", path, number)
        for j, i in enumerate(index):
            field = row[i].strip()
            if not field:
                continue
            try:
                values[k, j] = float(field)
            except ValueError:
                raise InputError(
                    f"{present[j]} is not a number: {field[:40]!r}", path, number
                ) from None
    if not len(values):
        raise InputError(f"the {what} has its header but no rows", path)
    lines = np.array([number for number, _ in numbered[1:]], dtype=int)
    return HeadedColumns({name: values[:, j] for j, name in enumerate(present)}, lines)


def increasing_times(t: np.ndarray, lines: np.ndarray, path: Path, what: str) -> None:
    """Raise :class:`InputError` naming the line of the first time that is not finite or not
    after the previous one."""
    bad = ~np.isfinite(t)
    if bad.any():
        raise InputError(f"{what} time is not a number", path, int(lines[np.argmax(bad)]))
    steps = np.flatnonzero(np.diff(t) <= 0)
    if steps.size:
        k = int(steps[0]) + 1
        raise InputError(
            f"{what} time {t[k]:.3f} s is not after the previous row's", path, int(lines[k])
        )


def truth_format(text: str, path: Path) -> TruthFormat:
    """The truth format of a file's ``text`` by :data:`AUTO_TRUTH_RULE`."""
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        if "UnixTimeMillis" in stripped or "LatitudeDegrees" in stripped:
            return TruthFormat.GSDC
        fields = [f for f in _SEPARATORS.split(stripped) if f]
        if "gps_time_s" in fields:
            return TruthFormat.LATLON
        try:
            numeric = bool([float(f) for f in fields])
        except ValueError:
            numeric = False
        if numeric:
            if len(fields) == 8:
                return TruthFormat.TUM
            if len(fields) == 5:
                return TruthFormat.LATLON
        raise InputError(
            f"cannot tell the ground-truth format from its first line ({len(fields)} fields): "
            f"expected {AUTO_TRUTH_RULE}",
            path,
        )
    raise InputError("the ground-truth file has no data rows", path)


def read_ground_truth(
    path: str | Path, fmt: TruthFormat | str = TruthFormat.AUTO, origin: EnuFrame | None = None
) -> GroundTruth:
    """Read a ground-truth file (module docstring); ``origin`` is the ENU frame of a TUM file's
    positions (None: positions are still read, but cannot be compared with geodetic ones), and
    the frame the CSV kinds are put in (None: their first row)."""
    fmt = checked(TruthFormat, fmt, "fmt")
    path = Path(path)
    text = read_text(path, "ground-truth file")
    if fmt is TruthFormat.AUTO:
        fmt = truth_format(text, path)
    if fmt is TruthFormat.TUM:
        trajectory = read_tum(path)
        return GroundTruth(trajectory.t, trajectory.positions, origin, None, "TUM")
    if fmt is TruthFormat.LATLON:
        return _read_latlon(text, path, origin)
    return _read_gsdc(text, path, origin)


def _read_latlon(text: str, path: Path, origin: EnuFrame | None) -> GroundTruth:
    first = next(
        (s for s in (line.strip() for line in text.splitlines()) if s and not s.startswith("#")),
        "",
    )
    if "gps_time_s" in first:
        wanted = ("gps_time_s", *LATITUDE_NAMES, *LONGITUDE_NAMES, *HEIGHT_NAMES, *COURSE_NAMES)
        table = headed_columns(text, path, "lat/lon truth CSV", wanted, ("gps_time_s",))
        picked = []
        for names in (LATITUDE_NAMES, LONGITUDE_NAMES, HEIGHT_NAMES):
            column = table.first(names)
            if column is None:
                raise InputError(f"the lat/lon truth CSV has no column {names[0]}", path, 1)
            picked.append(column)
        t, lines = table.columns["gps_time_s"], table.line
        lat, lon, height = picked
        course = table.first(COURSE_NAMES)
        source = "lat/lon CSV (gps_time_s)"
    else:
        rows, lines = _numeric_rows(text, path)
        week, tow = rows[:, 0], rows[:, 1]
        bad = (week != np.round(week)) | (week < 0) | (week > MAX_GPS_WEEK)
        bad |= (tow < 0) | (tow >= SECONDS_PER_WEEK)
        if bad.any():
            k = int(np.argmax(bad))
            raise InputError(
                f"GPS week {week[k]:g} / seconds of week {tow[k]:g} is not a GPS time",
                path,
                int(lines[k]),
            )
        t = week * SECONDS_PER_WEEK + tow
        lat, lon, height = rows[:, 2], rows[:, 3], rows[:, 4]
        course = None
        source = "lat/lon CSV (GPS week, seconds of week)"
    return _geodetic_truth(t, lat, lon, height, course, lines, path, origin, source)


def _numeric_rows(text: str, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The five numbers of each data line of a header-less lat/lon CSV, and the line numbers."""
    rows, lines = [], []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = [f for f in _SEPARATORS.split(stripped) if f]
        if len(fields) != 5:
            raise InputError(
                f"{len(fields)} fields, expected 5 (GPS week, seconds of week, lat, lon, h)",
                path,
                number,
            )
        try:
            rows.append([float(f) for f in fields])
        except ValueError as exc:
            raise InputError(f"a field is not a number ({exc})", path, number) from None
        lines.append(number)
    if not rows:
        raise InputError("the lat/lon truth CSV has no data rows", path)
    return np.array(rows, dtype=float), np.array(lines, dtype=int)


def _read_gsdc(text: str, path: Path, origin: EnuFrame | None) -> GroundTruth:
    table = headed_columns(
        text, path, "GSDC ground_truth.csv", (*GSDC_COLUMNS, "BearingDegrees"), GSDC_COLUMNS
    )
    c = table.columns
    t = unix_to_gps_seconds(c["UnixTimeMillis"] * 1e-3)
    course = c.get("BearingDegrees")
    return _geodetic_truth(
        t,
        c["LatitudeDegrees"],
        c["LongitudeDegrees"],
        c["AltitudeMeters"],
        course,
        table.line,
        path,
        origin,
        "GSDC ground_truth.csv",
    )


def _geodetic_truth(
    t: np.ndarray,
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    height_m: np.ndarray,
    course_deg: np.ndarray | None,
    lines: np.ndarray,
    path: Path,
    origin: EnuFrame | None,
    source: str,
) -> GroundTruth:
    """Checked geodetic rows as a :class:`GroundTruth` in ``origin``'s frame (else the first
    row's)."""
    increasing_times(t, lines, path, "ground-truth")
    low, high = HEIGHT_RANGE_M
    checks = (
        ("latitude", lat_deg, np.abs(lat_deg) <= 90.0),
        ("longitude", lon_deg, np.abs(lon_deg) <= 180.0),
        ("height", height_m, (height_m >= low) & (height_m <= high)),
    )
    for name, values, inside in checks:
        bad = ~(np.isfinite(values) & inside)
        if bad.any():
            k = int(np.argmax(bad))
            value = float(values[k])
            problem = "is blank" if np.isnan(value) else f"{value:g} is out of range"
            raise InputError(f"{name} {problem}", path, int(lines[k]))
    course = None
    if course_deg is not None:
        usable = np.isfinite(course_deg)
        if (np.abs(course_deg[usable]) > 360.0).any():
            k = int(np.argmax(usable & (np.abs(np.nan_to_num(course_deg)) > 360.0)))
            raise InputError(f"course {course_deg[k]:g} is not in degrees", path, int(lines[k]))
        course = np.radians(np.mod(course_deg, 360.0)) if usable.any() else None
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    frame = origin if origin is not None else EnuFrame(lat[0], lon[0], float(height_m[0]))
    enu = np.asarray(frame.geodetic_to_enu(lat, lon, height_m), dtype=float).reshape(-1, 3)
    return GroundTruth(np.asarray(t, dtype=float), enu, frame, course, source)


def sequence_origin(folder: str | Path) -> tuple[EnuFrame, Path | None]:
    """The ENU origin of a sequence folder's ``sequence.yaml`` and its ground-truth trajectory
    (None when the manifest names none)."""
    manifest = Manifest(read_manifest(folder))
    frame = EnuFrame(
        np.radians(manifest.number("origin", "lat_deg", low=-90.0, high=90.0)),
        np.radians(manifest.number("origin", "lon_deg", low=-180.0, high=180.0)),
        manifest.number("origin", "height_m", 0.0, low=HEIGHT_RANGE_M[0], high=HEIGHT_RANGE_M[1]),
    )
    truth = None
    if "ground_truth" in manifest.data:
        truth = manifest.file("ground_truth", "trajectory")
    return frame, truth
