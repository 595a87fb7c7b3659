"""An absolute heading from elsewhere that ``run --heading FILE`` uses instead of computing the
tightly coupled heading from GNSS."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.heading import HeadingTable


@dataclass(frozen=True)
class GivenHeading:
    """An absolute heading from elsewhere (a dual-antenna receiver, an INS, an earlier run's
    ``heading.csv``) that ``run`` uses instead of computing the tightly coupled heading from
    GNSS: ``table`` as :func:`vo_doppler.io.heading_csv.read_heading_csv` reads it,
    ``source`` (e.g. the file) names it in the summary."""

    table: HeadingTable
    source: str

    @property
    def has_tight(self) -> bool:
        """The table holds a tightly coupled heading (a ``heading.csv``; a minimal heading CSV
        holds its heading as the conventional one)."""
        return bool(self.table.tc_available.any())

    @property
    def has_calibration(self) -> bool:
        """The table holds a wheel scale and gyro bias at every row (a ``heading.csv``)."""
        table = self.table
        return bool(np.isfinite(table.wheel_scale).all() and np.isfinite(table.gyro_bias).all())

    def describe(self) -> str:
        """The summary's ``heading_source``."""
        what = (
            "its tightly coupled heading corrects the tightly coupled pipelines, its "
            "conventional heading the conventional ones"
            if self.has_tight
            else "its heading corrects the tightly coupled pipelines (there are no conventional "
            "ones)"
        )
        calibration = (
            "its wheel scale and gyro bias calibrate the vehicle signals"
            if self.has_calibration
            else "the wheel speed and yaw rate are used as recorded (no calibration)"
        )
        return f"given: {self.source}, not computed from GNSS; {what}; {calibration}"
