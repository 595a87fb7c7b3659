"""Read a sequence folder described by ``sequence.yaml`` (format ``vo-doppler-sequence/1``,
written by ``vo-doppler simulate``; any recording laid out the same way works) into the
recording model :class:`~vo_doppler.model.sequence.Sequence`.

Paths in the manifest are relative to its folder. Every sensor clock is mapped to GPS time by
``gps = sensor time + time_offset_s`` of that sensor.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.doppler_sigma import read_doppler_sigma
from vo_doppler.io.images import list_images, read_times
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.sequence import Sequence

log = logging.getLogger(__name__)

MANIFEST = "sequence.yaml"
FORMAT = "vo-doppler-sequence/1"


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """The parsed ``sequence.yaml`` of a folder (or the file itself), checked for its format."""
    path = Path(folder)
    if path.is_dir():
        path = path / MANIFEST
    try:
        manifest = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise InputError(f"cannot read the sequence manifest: {exc.strerror or exc}", path) from exc
    except yaml.YAMLError as exc:
        raise InputError(f"sequence manifest is not valid YAML: {exc}", path) from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        found = manifest.get("format") if isinstance(manifest, dict) else type(manifest).__name__
        raise InputError(f"not a {FORMAT} manifest (format: {found!r})", path)
    manifest["_path"] = path
    return manifest


def _section(manifest: dict[str, Any], name: str) -> dict[str, Any]:
    section = manifest.get(name)
    if not isinstance(section, dict):
        raise InputError(f"manifest has no '{name}' section", manifest["_path"])
    return section


def _entry(section: dict[str, Any], key: str, manifest: dict[str, Any], where: str):
    if key not in section:
        raise InputError(f"manifest section '{where}' lacks '{key}'", manifest["_path"])
    return section[key]


def read_sequence(folder: str | Path) -> Sequence:
    """All inputs of a sequence folder, on GPS time; ground truth when the folder has one."""
    manifest = read_manifest(folder)
    root = manifest["_path"].parent
    gnss_cfg = _section(manifest, "gnss")
    can_cfg = _section(manifest, "can")
    origin = _section(manifest, "origin")
    images, times, camera, camera_offset = [], np.zeros(0), None, 0.0
    if "camera" in manifest:  # a recording without video has no camera section
        camera_cfg = _section(manifest, "camera")
        camera_offset = float(camera_cfg.get("time_offset_s", 0.0))
        images = list_images(root / _entry(camera_cfg, "images", manifest, "camera"))
        times = read_times(root / _entry(camera_cfg, "times", manifest, "camera"), len(images))
        camera = read_camera(root / _entry(camera_cfg, "calib", manifest, "camera"))
    obs = read_obs(root / _entry(gnss_cfg, "obs", manifest, "gnss"))
    nav = _satellite_states(gnss_cfg, manifest, root)
    sigma_file = gnss_cfg.get("doppler_sigma")
    if float(gnss_cfg.get("time_offset_s", 0.0)) != 0.0:
        raise InputError("GNSS observations must be on GPS time (time_offset_s 0)", root)
    can_offset = float(can_cfg.get("time_offset_s", 0.0))
    short_frames = str(can_cfg.get("short_frames", "skip"))
    if short_frames not in ("skip", "pad"):
        raise InputError(f"can.short_frames is {short_frames!r}, not skip or pad", root)
    motion = read_can_motion(
        root / _entry(can_cfg, "log", manifest, "can"),
        root / _entry(can_cfg, "dbc", manifest, "can"),
        _entry(can_cfg, "yaw_rate", manifest, "can"),
        _entry(can_cfg, "wheel_speed", manifest, "can"),
        float(can_cfg.get("yaw_rate_sign", 1.0)),
        can_offset,
        can_offset,
        short_frames=short_frames,
    )
    if motion.yaw_rate is None or motion.speed is None or not len(motion.speed):
        raise InputError("CAN log gave no yaw rate or wheel speed", root / can_cfg["log"])
    enu = EnuFrame(
        np.radians(float(_entry(origin, "lat_deg", manifest, "origin"))),
        np.radians(float(_entry(origin, "lon_deg", manifest, "origin"))),
        float(origin.get("height_m", 0.0)),
    )
    lever_arm = _lever_arm(gnss_cfg.get("antenna_lever_arm_m", (0.0, 0.0, 0.0)), root)
    truth = None
    truth_cfg = manifest.get("ground_truth")
    if isinstance(truth_cfg, dict) and (root / truth_cfg.get("trajectory", "")).is_file():
        truth = read_tum(root / truth_cfg["trajectory"])
    return Sequence(
        name=str(manifest.get("name", root.name)),
        image_paths=images,
        image_times=times + camera_offset,
        camera=camera,
        observations=obs,
        navigation=nav,
        doppler_sigma=None if sigma_file is None else read_doppler_sigma(root / sigma_file),
        yaw_rate=motion.yaw_rate,
        wheel_speed=motion.speed,
        enu=enu,
        truth=truth,
        antenna_lever_arm_m=lever_arm,
        clock_offsets_s={
            "camera": camera_offset,
            "can": can_offset,
            "gnss": 0.0,
        },
    )


def _satellite_states(gnss_cfg: dict[str, Any], manifest: dict[str, Any], root: Path):
    """``gnss.orbits`` (SP3, with ``gnss.clocks``) when given, else ``gnss.nav``."""
    if "orbits" in gnss_cfg:
        clocks = gnss_cfg.get("clocks")
        return read_satellite_states(
            orbits=root / gnss_cfg["orbits"], clocks=None if clocks is None else root / clocks
        )
    nav_paths = _entry(gnss_cfg, "nav", manifest, "gnss")
    return read_satellite_states([root / p for p in np.atleast_1d(nav_paths)])


def _lever_arm(value, root: Path) -> tuple[float, float, float]:
    """``gnss.antenna_lever_arm_m``: three numbers (x forward, y left, z up, m)."""
    try:
        arm = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        arm = ()
    if len(arm) != 3 or not all(np.isfinite(arm)):
        raise InputError(f"gnss.antenna_lever_arm_m is {value!r}, not three numbers (m)", root)
    return arm
