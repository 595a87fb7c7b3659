"""A TU Chemnitz smartLoc raw CSV file → a standard sequence folder (``sequence.yaml``, format
``vo-doppler-sequence/1``, docs/sequence_format.md) that ``vo-doppler run`` reads.

Written (from :func:`vo_doppler.io.smartloc.read_smartloc`):

- ``gnss/<name>.obs``: RINEX 3.04 observations (``C1C L1C D1C S1C``, ``C2I …`` for BeiDou; the
  GLONASS channels in the header), values to the format's 1e-3;
- ``gnss/doppler_sigma.csv``: the receiver's σ of each Doppler as a range-rate σ (m/s, λ·σ_D),
  ``gnss.doppler_sigma``;
- ``gnss/doppler_nlos.csv``: one row per Doppler measurement, ``gps_time_s,sat,code,
  doppler_hz,wavelength_m,range_rate_mps,range_rate_sigma_mps,cn0_dbhz,nlos`` (nlos 1, 0, or −1
  for the file's ``#``): the per-row NLOS label kept for people and NLOS studies (not read by
  ``run``);
- ``vehicle/wheel_speed.csv`` and ``vehicle/yaw_rate.csv``: the ground truth's velocity and
  yaw rate (the reference system's, not an odometer's or a car gyro's: they carry no
  wheel-scale or gyro-bias error to calibrate), the ``vehicle:`` section;
- ``ground_truth.tum``: the ground truth as vehicle poses in the ENU frame of its first
  position (``origin``), the yaw the file's heading (0 = east, counter-clockwise), pitch and
  roll zero (not in the file);
- ``sequence.yaml``, with what the import found under ``smartloc:`` (for people; not read).

smartLoc ships **no navigation file**. Without one the manifest has no ``gnss`` section (the
observations are still written): ``run`` then runs the dead reckoning only, like a KITTI raw
drive without GNSS. Give the day's broadcast navigation (``--nav``, one or more RINEX files,
e.g. IGS's daily BRDC file for the recording's date) and the manifest gets a ``gnss`` section
with the files copied into ``gnss/``: ``run`` runs the GNSS pipelines too. The files are read
first, with the reader ``run`` uses, so a file ``run`` would refuse stops the import before
anything is written. smartLoc has no images: the folder has no ``camera`` section.
"""

from __future__ import annotations

import csv
import logging
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from vo_doppler.geo import EnuFrame
from vo_doppler.io.doppler_sigma import write_doppler_sigma
from vo_doppler.io.output_folder import check_output_folder, open_output_folder
from vo_doppler.io.rinex_write import observation_epochs, write_obs
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.io.sensor_csv import SPEED_COLUMN, YAW_RATE_COLUMN, write_sensor_csv
from vo_doppler.io.sequence import FORMAT, MANIFEST, origin_entry
from vo_doppler.io.smartloc import SmartLocRecording, read_smartloc
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

SPEED_CSV = "vehicle/wheel_speed.csv"
YAW_RATE_CSV = "vehicle/yaw_rate.csv"
GROUND_TRUTH = "ground_truth.tum"
DOPPLER_SIGMA = "gnss/doppler_sigma.csv"
DOPPLER_NLOS = "gnss/doppler_nlos.csv"
NLOS_HEADER = (
    "gps_time_s",
    "sat",
    "code",
    "doppler_hz",
    "wavelength_m",
    "range_rate_mps",
    "range_rate_sigma_mps",
    "cn0_dbhz",
    "nlos",
)


@dataclass(frozen=True)
class SmartLocImportSummary:
    folder: Path
    rows: int
    """Measurement rows of the file (one satellite each)."""
    epochs: int
    nlos: int
    line_of_sight: int
    unlabelled: int
    ground_truth_poses: int
    navigation: tuple[Path, ...]
    """The navigation files copied into the sequence (empty: no ``gnss`` section)."""
    problems: tuple[str, ...]


def import_smartloc(
    source: str | Path, output: str | Path, nav: Sequence[str | Path] = ()
) -> SmartLocImportSummary:
    """Write the sequence folder ``output`` from the smartLoc raw CSV ``source`` (module
    docstring). ``output`` is checked first (new, empty or an earlier import's, holding none of
    the inputs), and every input is read before anything is written."""
    source, output = Path(source), Path(output)
    nav = tuple(Path(p) for p in nav)
    check_output_folder(output, "import", [source, *nav])
    recording = read_smartloc(source)
    if nav:
        read_satellite_states(nav)
    truth = recording.truth
    frame = EnuFrame(float(truth.lat_rad[0]), float(truth.lon_rad[0]), float(truth.height_m[0]))
    positions = frame.geodetic_to_enu(truth.lat_rad, truth.lon_rad, truth.height_m)
    trajectory = Trajectory(
        truth.t, positions.reshape(-1, 3), Rotation.from_euler("z", truth.yaw_rad[:, None])
    )

    open_output_folder(output, "import")
    (output / "gnss").mkdir(exist_ok=True)
    (output / "vehicle").mkdir(exist_ok=True)
    obs_name = f"gnss/{source.stem}.obs"
    _write_rinex(output / obs_name, recording, frame.origin_ecef)
    write_doppler_sigma(output / DOPPLER_SIGMA, recording.doppler_sigma())
    _write_nlos(output / DOPPLER_NLOS, recording)
    write_sensor_csv(
        output / SPEED_CSV, SensorSeries(truth.t, truth.speed_mps, "speed", "m/s"), SPEED_COLUMN
    )
    write_sensor_csv(
        output / YAW_RATE_CSV,
        SensorSeries(truth.t, truth.yaw_rate_rad_s, "yaw_rate", "rad/s"),
        YAW_RATE_COLUMN,
    )
    write_tum(output / GROUND_TRUTH, trajectory)
    copied = []
    for path in nav:
        shutil.copyfile(path, output / "gnss" / path.name)
        copied.append(f"gnss/{path.name}")
    labels = _labels(recording)
    gnss = {"obs": obs_name, "nav": copied, "doppler_sigma": DOPPLER_SIGMA}
    manifest = {
        "format": FORMAT,
        "name": source.stem,
        "source": f"smartLoc raw CSV {source} (vo-doppler import smartloc)",
        "origin": origin_entry(frame),
        **({"gnss": gnss} if nav else {}),
        "vehicle": {"yaw_rate": YAW_RATE_CSV, "wheel_speed": SPEED_CSV, "time_offset_s": 0.0},
        "ground_truth": {"trajectory": GROUND_TRUTH},
        "smartloc": {
            "rows": recording.n_rows,
            "epochs": int(recording.observations.epoch_time.size),
            "navigation": "given: gnss section written"
            if nav
            else "none (smartLoc ships none): no gnss section; the observations are in "
            f"{obs_name} and {DOPPLER_SIGMA}; re-import with --nav for the GNSS pipelines",
            "doppler_nlos": f"{DOPPLER_NLOS}: per Doppler row the range rate (-wavelength x "
            "Doppler), its sigma and the NLOS label (1 NLOS, 0 line of sight, -1 unknown)",
            "nlos_rows": {
                "nlos": int((labels == 1).sum()),
                "line_of_sight": int((labels == 0).sum()),
                "unknown": int((labels == -1).sum()),
            },
            "vehicle": "the ground truth's velocity and yaw rate (not an odometer or a car gyro)",
            "ground_truth": "GT lon/lat/height in the ENU frame of the first epoch (origin); yaw "
            "= GT heading (0 = east, counter-clockwise); pitch and roll 0 (not in the file)",
            "problems": list(recording.problems),
        },
    }
    (output / MANIFEST).write_text(yaml.safe_dump(manifest, sort_keys=False, allow_unicode=True))
    return SmartLocImportSummary(
        output,
        recording.n_rows,
        int(recording.observations.epoch_time.size),
        int((labels == 1).sum()),
        int((labels == 0).sum()),
        int((labels == -1).sum()),
        len(trajectory),
        tuple(output / p for p in copied),
        recording.problems,
    )


def _doppler_rows(recording: SmartLocRecording) -> np.ndarray:
    """Indices of the observation rows that are Dopplers."""
    obs = recording.observations
    kinds = np.array([c[0] for c in obs.codes])
    return np.flatnonzero(kinds[obs.code] == "D")


def _labels(recording: SmartLocRecording) -> np.ndarray:
    """The NLOS label of each Doppler row."""
    return recording.observations.row_fields["nlos"][_doppler_rows(recording)]


def _write_rinex(path: Path, recording: SmartLocRecording, approx_ecef: np.ndarray) -> None:
    """The observations as RINEX 3.04, one line per (epoch, satellite)."""
    obs = recording.observations
    interval = float(np.median(np.diff(obs.epoch_time))) if obs.epoch_time.size > 1 else 0.0
    write_obs(
        path,
        observation_epochs(obs),
        approx_ecef,
        interval,
        marker_name="SMARTLOC",
        receiver="U-BLOX",
        glonass_channels=recording.glonass_channels,
        program="vo-doppler import",
        observer="TU Chemnitz smartLoc",
        antenna="UNKNOWN",
    )


def _write_nlos(path: Path, recording: SmartLocRecording) -> None:
    """``doppler_nlos.csv`` (module docstring)."""
    obs = recording.observations
    rows = _doppler_rows(recording)
    fields = obs.row_fields
    satellites = obs.satellites()
    strength = {
        (t, sat): value
        for t, sat, code, value in zip(
            obs.time.tolist(),
            satellites.tolist(),
            obs.code.tolist(),
            obs.value.tolist(),
            strict=True,
        )
        if obs.codes[code].startswith("S")
    }
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(NLOS_HEADER)
        for k in rows.tolist():
            cn0 = strength.get((float(obs.time[k]), str(satellites[k])))
            writer.writerow(
                (
                    f"{obs.time[k]:.3f}",
                    satellites[k],
                    obs.codes[obs.code[k]],
                    f"{obs.value[k]:.4f}",
                    f"{fields['wavelength_m'][k]:.9f}",
                    f"{fields['range_rate_mps'][k]:.6f}",
                    f"{fields['range_rate_sigma_mps'][k]:.6g}",
                    "" if cn0 is None else f"{cn0:g}",
                    int(fields["nlos"][k]),
                )
            )
