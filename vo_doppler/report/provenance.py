"""What a run report says about its inputs and settings: the data (synthetic or recorded,
sensors, duration, distance), the command line, the version and the configuration in people
units (degrees, km/h where a person expects them; the library keeps SI units and radians)."""

from __future__ import annotations

import dataclasses
import shlex
import sys
from dataclasses import dataclass

import numpy as np

from vo_doppler import __version__
from vo_doppler.errors import shown
from vo_doppler.model.sequence import Sequence
from vo_doppler.run import RunConfig
from vo_doppler.units import in_people_units

SYNTHETIC_KEYS = ("scenario", "command")
"""Manifest keys only ``vo-doppler simulate`` writes: their presence marks a simulated drive."""


@dataclass
class DataDescription:
    """The recording as the report presents it (``None``: not known)."""

    name: str
    kind: str
    """One of "synthetic", "recorded" or "" (no manifest given: not stated)."""
    origin: str
    """How the data came to be, e.g. "simulated by: vo-doppler simulate …" or "recorded"."""
    sensors: list[str]
    duration_s: float
    distance_m: float | None
    distance_source: str


def is_synthetic(manifest: dict | None) -> bool:
    """A drive is simulated when its manifest has a simulator's key (:data:`SYNTHETIC_KEYS`)."""
    return manifest is not None and any(key in manifest for key in SYNTHETIC_KEYS)


def sensors_present(sequence: Sequence) -> list[str]:
    """The sensors of a recording in words, e.g. "camera (570 images, 15.0 frames/s)"."""
    sensors = []
    if sequence.has_camera:
        n = len(sequence.image_paths)
        span = float(sequence.image_times[-1] - sequence.image_times[0]) if n > 1 else 0.0
        rate = f", {(n - 1) / span:.1f} frames/s" if span > 0 else ""
        sensors.append(f"monocular camera ({n} images{rate})")
    if sequence.has_gnss:
        epochs = len(sequence.observations.epoch_time)
        systems = "".join(sorted(sequence.observations.header.obs_types)) or "?"
        sensors.append(
            f"GNSS receiver ({epochs} epochs, systems {systems}, pseudorange and Doppler)"
        )
    sensors.append(f"wheel speed ({len(sequence.wheel_speed)} samples)")
    sensors.append(f"yaw-rate gyro ({len(sequence.yaw_rate)} samples)")
    if sequence.truth is not None:
        sensors.append(f"ground truth ({len(sequence.truth)} poses)")
    return sensors


def describe_data(
    sequence: Sequence, manifest: dict | None, driven_m: float | None = None
) -> DataDescription:
    """The data of a run. ``driven_m`` (e.g. the wheel-speed integral) stands in for the
    distance when the recording has no ground truth."""
    times = [sequence.wheel_speed.t, sequence.yaw_rate.t]
    if sequence.has_gnss:
        times.append(sequence.observations.epoch_time)
    if sequence.has_camera:
        times.append(sequence.image_times)
    begin = max(float(t[0]) for t in times if len(t))
    end = min(float(t[-1]) for t in times if len(t))
    kind = "synthetic" if is_synthetic(manifest) else "recorded" if manifest is not None else ""
    if kind == "synthetic":
        command = " ".join(str(manifest.get("command", "")).split())
        origin = f"synthetic: simulated by {command}" if command else "synthetic (simulated)"
    elif kind == "recorded":
        origin = "recorded (the manifest names no simulator)"
    else:
        origin = "not stated (no manifest given to the report)"
    if sequence.truth is not None and len(sequence.truth) > 1:
        distance, source = float(sequence.truth.path_length), "ground truth"
    elif driven_m is not None:
        distance, source = driven_m, "calibrated wheel speed"
    else:
        distance, source = None, "unknown"
    return DataDescription(
        sequence.name,
        kind,
        origin,
        sensors_present(sequence),
        max(end - begin, 0.0),
        distance,
        source,
    )


def command_line(argv: list[str] | None = None) -> str:
    """The command as typed (program name shortened to ``vo-doppler``), shell-quoted; the
    bytes of a name that is not UTF-8 as ``\\xff`` escapes (:func:`~vo_doppler.errors.shown`)."""
    argv = sys.argv if argv is None else argv
    return shlex.join(["vo-doppler", *(shown(arg) for arg in argv[1:])])


def version() -> str:
    return f"vo-doppler {__version__}"


def _people_value(name: str, value) -> tuple[str, str]:
    """(name, value) in people units: an angle in degrees, from the unit its name ends in
    (:func:`~vo_doppler.units.in_people_units`: ``gate_rad`` becomes ``gate_deg``)."""
    shown, value, symbol = in_people_units(name, value)
    unit, name = (f" {symbol}" if shown != name else ""), shown
    if unit and isinstance(value, float) and np.isfinite(value):
        return name, f"{value:.4g}{unit}"
    if isinstance(value, float):
        return name, f"{value:.4g}"
    return name, str(value)


GNSS_CONFIG = ("systems", "elevation_mask", "heading.", "correction.")
"""RunConfig settings (dotted-name prefixes) of the GNSS stages, the heading and its correction:
not run on a recording without GNSS."""
CAMERA_CONFIG = ("vo.",)
"""RunConfig settings of the VO: not run on a recording without a camera."""


def config_rows(config: RunConfig, camera: bool = True, gnss: bool = True) -> list[tuple[str, str]]:
    """Every RunConfig setting as (dotted name, value for people), angles in degrees; those of
    the stages that did not run (the VO without a ``camera``, the GNSS, heading and correction
    stages without ``gnss``: :data:`CAMERA_CONFIG`, :data:`GNSS_CONFIG`) left out."""
    rows: list[tuple[str, str]] = []

    def walk(prefix: str, obj) -> None:
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if dataclasses.is_dataclass(value):
                walk(f"{prefix}{f.name}.", value)
            else:
                name, shown = _people_value(f.name, value)
                rows.append((prefix + name, shown))

    walk("", config)
    skipped = (() if camera else CAMERA_CONFIG) + (() if gnss else GNSS_CONFIG)
    return [(name, value) for name, value in rows if not name.startswith(skipped)]


def main_settings(
    config: RunConfig, camera: bool = True, gnss: bool = True
) -> list[tuple[str, str]]:
    """The settings a person chooses on the command line, in people units: only those of the
    stages that ran (the VO window with a ``camera``; the satellites, the heading and its
    correction with ``gnss``; the dead reckoning's rate always)."""
    correction = config.correction
    method = {
        "kalman": "adaptive blend (Kalman filter on the VO heading offset)",
        "window": "[TK18] window method, Eq. 11–13",
    }[correction.method]
    if not camera:
        method = method.replace("the VO heading offset", "the heading offset")
    smoothing = "smoothed (forward filter and backward smoother)"
    if correction.method == "kalman" and not correction.blend.smooth:
        smoothing = "causal (forward filter only)"
    rows = []
    if gnss:
        rows += [
            ("GNSS systems", config.systems),
            ("elevation mask", f"{np.degrees(config.elevation_mask_rad):.1f} deg"),
        ]
    if camera:
        rows.append(("VO window", f"{config.vo.window_size} frames"))
    rows.append(("dead-reckoning rate", f"{config.dead_reckoning_rate_hz:g} Hz"))
    if gnss:
        rows += [
            (
                "heading correction",
                method + ("; " + smoothing if correction.method == "kalman" else ""),
            ),
            (f"{'VO' if camera else 'dead-reckoning'} heading compared as", correction.reference),
            (
                "tightly coupled heading used when σ <",
                f"{np.degrees(correction.tc_max_sigma_rad):.1f} deg",
            ),
            ("heading calibration", config.heading.calibration),
            ("tight heading settings", _heading_settings(config)),
        ]
    return rows


def _heading_settings(config: RunConfig) -> str:
    """The tight heading's settings in words: the method that ran, or ``auto``'s rule when the
    configuration was not resolved for a recording (:meth:`RunConfig.for_sequence`)."""
    heading = config.heading
    if heading.robust_below_rate_hz is not None:
        return f"auto: robust below {heading.robust_below_rate_hz:g} Hz GNSS, else snooping"
    smoother = ", smoothed through the gyro" if heading.smoother.enabled else ""
    return heading.method + smoother
