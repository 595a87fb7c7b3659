"""One entry for GNSS observation files of any supported format, recognised by content.

- u-blox UBX (binary, a ``B5 62`` sync in the first 4 KiB, not text) → :mod:`.ubx`, with the
  GPS ephemerides decoded from its RXM-SFRBX subframes;
- Android GnssLogger text (a ``# Raw,`` header line or ``Raw,`` rows) → :mod:`.android`;
- GSDC ``device_gnss.csv`` (first line ``MessageType,…`` with the derived columns) →
  :mod:`.gsdc` (its satellite states are not returned here: use ``read_device_gnss``);
- anything else is read as RINEX 2/3 observations.
"""

from __future__ import annotations

from pathlib import Path

from vo_doppler.errors import InputError
from vo_doppler.io.android import read_gnsslogger
from vo_doppler.io.gsdc import read_device_gnss
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.ubx import SYNC, read_ubx
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations

SNIFF_BYTES = 4096


def sniff_format(path: Path) -> str:
    """'ubx', 'gnsslogger', 'gsdc' or 'rinex' from the first bytes of the file."""
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
    return "rinex"


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
    return read_obs(path), None
