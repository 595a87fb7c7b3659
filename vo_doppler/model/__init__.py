"""The plain dataclasses every stage takes and returns: ``from vo_doppler.model import
SensorSeries, Trajectory, …`` (README, "Library").

The names load their module on first use (PEP 562 ``__getattr__``): importing one model
module, as every reader does, must not load them all (``Trajectory`` alone brings in scipy,
about half a second a process).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

EXPORTS: dict[str, str] = {
    "Camera": "camera",
    "DopplerRows": "doppler",
    "ReportedSigma": "doppler_sigma",
    "SppSolution": "gnss_solutions",
    "GivenHeading": "given_heading",
    "VelocitySolution": "gnss_solutions",
    "HeadingTable": "heading",
    "NavRecords": "navigation",
    "Navigation": "navigation",
    "ObsHeader": "observations",
    "Observations": "observations",
    "PreciseOrbits": "precise_orbits",
    "SatelliteClocks": "precise_orbits",
    "ReceiverSolution": "receiver_solution",
    "RowSigma": "row_sigma",
    "SatelliteTable": "satellite_table",
    "Sequence": "sequence",
    "SensorSeries": "series",
    "SpanBound": "time_span",
    "TimeSpan": "time_span",
    "Trajectory": "trajectory",
    "VehicleSignals": "vehicle_signals",
}
"""Public dataclass → the module of this package that defines it."""

__all__ = [
    "Camera",
    "DopplerRows",
    "GivenHeading",
    "HeadingTable",
    "NavRecords",
    "Navigation",
    "ObsHeader",
    "Observations",
    "PreciseOrbits",
    "ReceiverSolution",
    "ReportedSigma",
    "RowSigma",
    "SatelliteClocks",
    "SatelliteTable",
    "SensorSeries",
    "Sequence",
    "SpanBound",
    "SppSolution",
    "TimeSpan",
    "Trajectory",
    "VehicleSignals",
    "VelocitySolution",
]
"""The names of ``EXPORTS`` (a literal list, for type checkers and linters)."""

if TYPE_CHECKING:
    from vo_doppler.model.camera import Camera
    from vo_doppler.model.doppler import DopplerRows
    from vo_doppler.model.doppler_sigma import ReportedSigma
    from vo_doppler.model.given_heading import GivenHeading
    from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
    from vo_doppler.model.heading import HeadingTable
    from vo_doppler.model.navigation import Navigation, NavRecords
    from vo_doppler.model.observations import Observations, ObsHeader
    from vo_doppler.model.precise_orbits import PreciseOrbits, SatelliteClocks
    from vo_doppler.model.receiver_solution import ReceiverSolution
    from vo_doppler.model.row_sigma import RowSigma
    from vo_doppler.model.satellite_table import SatelliteTable
    from vo_doppler.model.sequence import Sequence
    from vo_doppler.model.series import SensorSeries
    from vo_doppler.model.time_span import SpanBound, TimeSpan
    from vo_doppler.model.trajectory import Trajectory
    from vo_doppler.model.vehicle_signals import VehicleSignals


def __getattr__(name: str) -> type:
    module = EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(EXPORTS))
