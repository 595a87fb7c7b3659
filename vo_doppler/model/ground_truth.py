"""A ground-truth track to score GNSS outputs against: positions in a local ENU frame on GPS time,
and the file's own course where it has one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import EnuFrame


@dataclass(frozen=True)
class GroundTruth:
    """Positions ``enu`` (n, 3) in metres at GPS times ``t`` (s, strictly increasing).

    ``frame`` is the ENU frame of the positions (None for a TUM file read without its origin:
    velocities and courses are still right, positions cannot be compared with geodetic ones).
    ``course_rad`` is the file's own course (clockwise from north, rad; NaN where a row has
    none), or None when the file carries no heading and the course must come from the
    positions. ``source`` says what kind of file it came from, for people.
    """

    t: np.ndarray
    enu: np.ndarray
    frame: EnuFrame | None
    course_rad: np.ndarray | None
    source: str

    def __post_init__(self) -> None:
        if self.enu.shape != (self.t.size, 3):
            raise ValueError(f"enu has shape {self.enu.shape}, expected ({self.t.size}, 3)")
        if self.course_rad is not None and self.course_rad.shape != self.t.shape:
            raise ValueError("course_rad must have one value per time")

    def __len__(self) -> int:
        return int(self.t.size)
