"""One entry for GNSS observation files of any supported format, recognised by content.

- u-blox UBX (binary, a ``B5 62`` sync in the first 4 KiB, not text) → :mod:`.ubx`, with the
  ephemerides decoded from its RXM-SFRBX navigation data (GPS, QZSS, Galileo, BeiDou, GLONASS);
- Android GnssLogger text (a ``# Raw,`` header line or ``Raw,`` rows) → :mod:`.android`;
- GSDC ``device_gnss.csv`` (first line ``MessageType,…`` with the derived columns) →
  :mod:`.gsdc` (its satellite states are not returned here: use ``read_device_gnss``);
- a TU Chemnitz smartLoc raw CSV (first line ``GPSWeek …;…(doMes)…;NLOS …``) →
  :mod:`.smartloc` (its ground truth is not returned here: use ``read_smartloc``, or
  ``vo-doppler import smartloc`` for a sequence folder);
- RINEX 2/3/4 observations (``RINEX VERS`` in the first bytes, plain or Hatanaka), or a
  compressed file (gzip, Unix compress, bzip2, zip: read as compressed RINEX);
- anything else is an :class:`InputError` that lists the readable formats and the command for
  each (:data:`READABLE`), instead of a RINEX reader's complaint about a file that is not one.
"""

from __future__ import annotations

from pathlib import Path

from vo_doppler.errors import InputError
from vo_doppler.io.android import read_gnsslogger
from vo_doppler.io.gsdc import read_device_gnss
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.smartloc import is_smartloc_header, read_smartloc
from vo_doppler.io.ubx import SYNC, read_ubx
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations

SNIFF_BYTES = 4096
COMPRESSED_MAGIC = (b"\x1f\x8b", b"\x1f\x9d", b"BZh", b"PK\x03\x04")
"""gzip, Unix compress, bzip2, zip: left to the RINEX reader, which says what it can open."""
READABLE = (
    ("RINEX 2/3/4 observations (plain, gzip, Hatanaka)", "vo-doppler gnss velocity FILE --nav NAV"),
    ("u-blox UBX with RXM-RAWX", "vo-doppler gnss velocity FILE [--nav NAV]"),
    ("Android GnssLogger .txt", "vo-doppler gnss velocity FILE --nav NAV"),
    ("GSDC device_gnss.csv", "vo-doppler gnss velocity FILE --nav NAV"),
    (
        "TU Chemnitz smartLoc raw CSV",
        "vo-doppler gnss velocity FILE --nav NAV, or vo-doppler import smartloc FILE -o SEQ",
    ),
    ("comma2k19 segment folder", "vo-doppler import comma2k19 SEGMENT --orbits SP3 -o SEQ"),
    ("KITTI raw drive folder", "vo-doppler import kitti-raw DRIVE -o SEQ"),
    ("ROS 1/2 bag", "vo-doppler import rosbag BAG -o SEQ [--list-topics]"),
)
"""The GNSS recordings the toolkit reads and the command for each (docs/formats.md)."""


def unknown_format_message(head: bytes) -> str:
    """Why a file is refused, with its first line and the readable formats."""
    first = head.split(b"\n", 1)[0].decode("utf-8", "replace").strip()
    shown = first[:60] + ("…" if len(first) > 60 else "")
    listing = "; ".join(f"{name}: {command}" for name, command in READABLE)
    return (
        f"not a GNSS observation file of a format this toolkit reads (first line {shown!r}). "
        f"Readable: {listing} (docs/formats.md)"
    )


def sniff_format(path: Path) -> str:
    """'ubx', 'gnsslogger', 'gsdc', 'smartloc' or 'rinex' from the first bytes of the file; an
    :class:`InputError` listing the readable formats for anything else."""
    try:
        with path.open("rb") as handle:
            head = handle.read(SNIFF_BYTES)
    except OSError as exc:
        raise InputError(f"cannot read: {exc}", path) from exc
    if SYNC in head and b"\x00" in head:
        return "ubx"
    text = head.decode("latin-1")
    if text.startswith("MessageType,") and "ArrivalTimeNanosSinceGpsEpoch" in text:
        return "gsdc"
    if "# Raw," in text or "\nRaw," in text:
        return "gnsslogger"
    if is_smartloc_header(head.split(b"\n", 1)[0].decode("utf-8", "replace")):
        return "smartloc"
    if b"RINEX VERS" in head or head.startswith(COMPRESSED_MAGIC):
        return "rinex"
    raise InputError(unknown_format_message(head), path)


def read_observation_file(path: str | Path) -> tuple[Observations, Navigation | None]:
    """Observations of a file of any supported format, and the navigation data it carries."""
    path = Path(path)
    kind = sniff_format(path)
    if kind == "ubx":
        recording = read_ubx(path)
        if recording.observations is None:
            raise InputError("UBX file without RXM-RAWX measurements", path)
        return recording.observations, recording.navigation
    if kind == "gnsslogger":
        return read_gnsslogger(path).observations, None
    if kind == "gsdc":
        return read_device_gnss(path).observations, None
    if kind == "smartloc":
        return read_smartloc(path).observations, None
    return read_obs(path), None
