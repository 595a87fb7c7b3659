"""Sequence folders from the real Hong Kong urban-canyon recordings in ``../shared/data``.

    python benchmarks/real_sequences.py OUT_DIR [--shared DIR] [--seed N]

The recordings have GNSS observations and a reference trajectory but no vehicle signals; the
signals are synthesised from the reference (issue 29's recipe, so that every figure is
comparable): yaw rate = the time derivative of the reference course (central differences of
the 1 Hz positions in local ENU, the course held through stops below 1 m/s) + 0.5 °/s bias +
white noise of 0.05 °/s; wheel speed = the reference speed × 1.02 + white noise of 0.02 m/s,
clipped at zero; both at 10 Hz on GPS time, over the span the reference covers. The
observation and navigation files are copied into each folder (a sequence reads only its own
folder); the folders are written outside the repository, since the recordings' licences are
not the project's.

* ``hk_tst_canyon_drive``: u-blox M8T, GPS + BeiDou, 1 Hz, reference for the first half;
* ``hk_tst_static_f9p``: u-blox F9P standing 16 min: speed zero, yaw rate bias and noise only;
* ``hk_klt_f9p_drive``: u-blox F9P driving 3.4 min through Kowloon Tong, **no ground truth**.
  Its reference comes from the receiver itself (:func:`self_reference`): the conventional
  Doppler velocities of the epochs the GNSS stage flags valid (``vo-doppler gnss``, a-priori
  σ), each ENU component a running median over ``REFERENCE_WINDOW_S``, the course held
  through stops as above. The folder has no ground truth; the reference speed is written
  beside the signals (``SELF_REFERENCE_FILE``) so that ``benchmarks/real_heading.py`` can tell
  moving epochs. Figures on it are self-consistency (the tight heading against the same
  receiver's conventional headings), not accuracy: the synthesised gyro turns as the
  receiver's own velocity does.
"""

from __future__ import annotations

import argparse
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from vo_doppler.eval.gnss_scores import held_course
from vo_doppler.geo import EnuFrame, course_to_yaw, ecef_to_geodetic
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.io.sensor_csv import read_sensor_csv, write_sensor_csv
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.run import RunConfig

ROOT = Path(__file__).resolve().parents[1]
GPS_WEEK_S = 604800.0
SIGNAL_RATE_HZ = 10.0
GYRO_BIAS_RAD_S = float(np.radians(0.5))
GYRO_NOISE_RAD_S = float(np.radians(0.05))
WHEEL_SCALE = 1.02
WHEEL_NOISE_MPS = 0.02
COURSE_HOLD_MPS = 1.0
MOVING_MPS = 3.0
STANDSTILL_MPS = 0.2
REFERENCE_WINDOW_S = 5.0
"""Span of the running median that smooths a self-made reference (5 epochs at 1 Hz: a single
outlying epoch never moves it, and it keeps a steady turn's course, a monotone sequence)."""
SELF_REFERENCE_FILE = "self_reference_speed.csv"
"""The horizontal speed (m/s) of a reference made from the recording's own GNSS, beside the
synthesised signals; its presence marks a folder whose figures are self-consistency only."""


@dataclass(frozen=True)
class Recording:
    """One recording of the shared folder: observation, navigation and reference files."""

    folder: str
    obs: str
    nav: tuple[str, ...]
    truth: str | None
    """The reference CSV; None: the reference comes from the receiver (:func:`self_reference`)."""
    static_span_tow: tuple[float, float] | None = None
    """For a receiver that stands still throughout: the seconds of week its observations span
    (the reference then gives the point; its first column, GPS week, is ``week``)."""
    week: int | None = None


HK_TST_CANYON = Recording(
    "hk_tst_canyon_drive",
    "COM3_190428_124409.obs",
    ("hksc1180.19n", "hksc1180.19b"),
    "groundTruth_TST_first_half.csv",
)
HK_TST_STATIC = Recording(
    "hk_tst_static_f9p",
    "2020_06_03_TST_03.obs",
    tuple(f"hksc155{h}.20{s}" for h in "cd" for s in "nglb"),
    "groundTruth_TST.csv",
    static_span_tow=(270147.0, 271133.0),
    week=2108,
)
HK_KLT_DRIVE = Recording("hk_klt_f9p_drive", "20210610.klt1.ublox.f9p.obs", ("hksc1610.nav",), None)
RECORDINGS = (HK_TST_CANYON, HK_TST_STATIC, HK_KLT_DRIVE)


def shared_data_dir() -> Path:
    return Path(os.environ.get("VO_DOPPLER_SHARED_DATA", ROOT.parent / "shared" / "data"))


def read_reference(recording: Recording, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """GPS seconds and (lat °, lon °, h m) rows of a reference CSV (GPS week, seconds of week,
    latitude, longitude, ellipsoidal height; no header). The static recording's file repeats
    the seconds of week in its week column and covers only part of the span: its one point is
    spread over the whole span at 1 Hz."""
    rows = np.loadtxt(path, delimiter=",", ndmin=2)
    if recording.static_span_tow is None:
        return rows[:, 0] * GPS_WEEK_S + rows[:, 1], rows[:, 2:5]
    tow = np.arange(*recording.static_span_tow)
    return recording.week * GPS_WEEK_S + tow, np.repeat(rows[:1, 2:5], tow.size, axis=0)


def reference_course(t: np.ndarray, enu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal speed (m/s) and yaw (rad, counter-clockwise from east, unwrapped) of the
    reference by central differences, the course held through stops below ``COURSE_HOLD_MPS``
    (:func:`~vo_doppler.eval.gnss_scores.held_course`, as ``eval gnss`` scores it)."""
    velocity = np.gradient(enu, t, axis=0)
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    course = held_course(velocity, None, COURSE_HOLD_MPS)
    return speed, np.unwrap(np.nan_to_num(course_to_yaw(course)))


def running_median(t: np.ndarray, values: np.ndarray, window_s: float) -> np.ndarray:
    """Per time of ``t``: the median of the ``values`` rows (NaN rows ignored) within
    ``window_s``/2 of it, per column; NaN where the window holds no finite row."""
    out = np.full(values.shape, np.nan)
    for i, centre in enumerate(t):
        near = values[np.abs(t - centre) <= 0.5 * window_s]
        near = near[np.all(np.isfinite(near), axis=1)]
        if near.size:
            out[i] = np.median(near, axis=0)
    return out


def self_reference(velocity: VelocitySolution) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal speed (m/s) and yaw (rad, unwrapped) at the velocity's epochs from the
    recording's own conventional Doppler velocities: the valid epochs' east and north
    components, each a running median over ``REFERENCE_WINDOW_S`` (epochs that are not valid
    take their neighbours'), the course held through stops below ``COURSE_HOLD_MPS``. Not
    ground truth: the receiver's own errors are in it."""
    horizontal = np.where(velocity.valid[:, None], velocity.velocity_enu[:, :2], np.nan)
    smooth = running_median(velocity.t, horizontal, REFERENCE_WINDOW_S)
    if not np.isfinite(smooth).all():
        raise SystemExit("the conventional velocity leaves epochs without a valid neighbour")
    speed = np.hypot(smooth[:, 0], smooth[:, 1])
    course = held_course(smooth, None, COURSE_HOLD_MPS)
    return speed, np.unwrap(np.nan_to_num(course_to_yaw(course)))


def gnss_reference(folder: Path, recording: Recording) -> tuple[np.ndarray, np.ndarray, tuple]:
    """(epoch times, (speed, yaw) of :func:`self_reference`, origin (lat °, lon °, h m): the
    first valid SPP fix) from the GNSS stage of ``run`` on the folder's copied files."""
    config = RunConfig()
    gnss = gnss_velocity(
        read_obs(folder / "gnss" / recording.obs),
        read_satellite_states([folder / "gnss" / name for name in recording.nav]),
        config.systems,
        config.elevation_mask_rad,
    )
    first = np.flatnonzero(gnss.spp.valid)[0]
    lat, lon, height = ecef_to_geodetic(gnss.spp.position_ecef[first])
    origin = (float(np.degrees(lat)), float(np.degrees(lon)), float(height))
    return gnss.velocity.t, self_reference(gnss.velocity), origin


def read_self_reference(folder: Path) -> SensorSeries | None:
    """The reference speed of a folder whose reference came from its own GNSS; None for a
    folder with a real one."""
    path = Path(folder) / SELF_REFERENCE_FILE
    return read_sensor_csv(path, "speed_mps") if path.exists() else None


def vehicle_signals(
    t: np.ndarray, speed: np.ndarray, yaw: np.ndarray, seed: int
) -> tuple[SensorSeries, SensorSeries]:
    """(yaw rate rad/s, wheel speed m/s) at ``SIGNAL_RATE_HZ`` over the reference's span."""
    rng = np.random.default_rng(seed)
    t_signal = np.arange(t[0], t[-1] + 1e-9, 1.0 / SIGNAL_RATE_HZ)
    rate = np.gradient(yaw, t)
    yaw_rate = np.interp(t_signal, t, rate) + GYRO_BIAS_RAD_S
    yaw_rate += GYRO_NOISE_RAD_S * rng.standard_normal(t_signal.size)
    wheel = np.interp(t_signal, t, speed) * WHEEL_SCALE
    wheel = np.clip(wheel + WHEEL_NOISE_MPS * rng.standard_normal(t_signal.size), 0.0, None)
    return SensorSeries(t_signal, yaw_rate), SensorSeries(t_signal, wheel)


def write_sequence(recording: Recording, shared: Path, out: Path, seed: int = 0) -> Path:
    """Write the sequence folder of ``recording`` under ``out`` and return it."""
    source = shared / recording.folder
    folder = out / recording.folder
    (folder / "gnss").mkdir(parents=True, exist_ok=True)
    for name in (recording.obs, *recording.nav):
        shutil.copyfile(source / name, folder / "gnss" / name)
    synthesised = {
        "seed": seed,
        "gyro_bias_dps": float(np.degrees(GYRO_BIAS_RAD_S)),
        "wheel_scale": WHEEL_SCALE,
    }
    truth = {}
    if recording.truth is None:
        t, (speed, yaw), origin = gnss_reference(folder, recording)
        write_sensor_csv(folder / SELF_REFERENCE_FILE, SensorSeries(t, speed), "speed_mps")
        synthesised["reference"] = "the receiver's own valid conventional Doppler velocities"
    else:
        t, geodetic = read_reference(recording, source / recording.truth)
        origin = tuple(float(value) for value in geodetic[0])
        frame = EnuFrame(*np.radians(geodetic[0, :2]), float(geodetic[0, 2]))
        enu = frame.geodetic_to_enu(
            np.radians(geodetic[:, 0]), np.radians(geodetic[:, 1]), geodetic[:, 2]
        )
        speed, yaw = reference_course(t, enu)
        rotation = Rotation.from_euler("z", yaw[:, None])
        write_tum(folder / "ground_truth.tum", Trajectory(t, enu, rotation))
        truth = {"ground_truth": {"trajectory": "ground_truth.tum"}}
    yaw_rate, wheel = vehicle_signals(t, speed, yaw, seed)
    write_sensor_csv(folder / "yaw_rate.csv", yaw_rate, "yaw_rate_rad_s")
    write_sensor_csv(folder / "wheel_speed.csv", wheel, "speed_mps")
    manifest = {
        "format": "vo-doppler-sequence/1",
        "name": recording.folder,
        "origin": dict(zip(("lat_deg", "lon_deg", "height_m"), origin, strict=True)),
        "gnss": {"obs": f"gnss/{recording.obs}", "nav": [f"gnss/{n}" for n in recording.nav]},
        "vehicle": {"yaw_rate": "yaw_rate.csv", "wheel_speed": "wheel_speed.csv"},
        **truth,
        "synthesised": synthesised,
    }
    (folder / "sequence.yaml").write_text(yaml.safe_dump(manifest, sort_keys=False))
    return folder


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--shared", type=Path, default=shared_data_dir())
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    for recording in RECORDINGS:
        print(write_sequence(recording, args.shared, args.out, args.seed))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
