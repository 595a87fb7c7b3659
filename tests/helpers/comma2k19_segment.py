"""A small synthetic comma2k19 segment (10 s of a car driving east at 10 m/s) that
``vo-doppler import comma2k19`` accepts, and the SP3 file covering it: the base that the
bad-array tests and the comma2k19 fuzz family mutate one array at a time."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from tests.helpers.precise_text import sp3_text
from vo_doppler.geo import EnuFrame
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

WEEK, TOW0, LOG0 = 2012, 404106.0, 100.0
"""GPS week and second of week of the first frame, and its log-clock time (s)."""
ORIGIN = EnuFrame(np.radians(37.72), np.radians(-122.47), 30.0)
FRAMES, FRAME_STEP_S = 200, 0.05
IMU_STEP_S = 0.01
GNSS_EPOCHS, GNSS_STEP_S = 50, 0.2
SATELLITES = (2, 5, 13, 15, 24)
FLIP = np.array([1.0, -1.0, -1.0])
"""Device frame (x forward, y right, z down) ↔ x forward, y left, z up."""


def npy_bytes(array: np.ndarray) -> bytes:
    """``array`` as the bytes of an ``.npy`` file (comma2k19 stores them without a suffix)."""
    out = io.BytesIO()
    np.save(out, array, allow_pickle=False)
    return out.getvalue()


def segment_arrays() -> dict[str, np.ndarray]:
    """Relative path (``global_pose/frame_times`` …) → array of the synthetic segment."""
    t = LOG0 + FRAME_STEP_S * np.arange(FRAMES)
    speed = 10.0
    east = np.column_stack([speed * (t - LOG0), np.zeros(FRAMES), np.zeros(FRAMES)])
    to_ecef = ORIGIN.rotation.T
    velocity = np.tile(to_ecef @ np.array([speed, 0.0, 0.0]), (FRAMES, 1))
    device_to_ecef = np.tile(to_ecef * FLIP, (FRAMES, 1, 1))  # vehicle axes = ENU: east ahead
    quaternion_xyzw = Rotation.from_matrix(device_to_ecef).as_quat()
    arrays = {
        "global_pose/frame_times": t,
        "global_pose/frame_gps_times": np.column_stack(
            [np.full(FRAMES, float(WEEK)), TOW0 + (t - LOG0)]
        ),
        "global_pose/frame_positions": ORIGIN.enu_to_ecef(east),
        "global_pose/frame_velocities": velocity,
        "global_pose/frame_orientations": quaternion_xyzw[:, [3, 0, 1, 2]],
    }
    t_imu = LOG0 + IMU_STEP_S * np.arange(int(FRAMES * FRAME_STEP_S / IMU_STEP_S))
    n_imu = t_imu.size
    arrays["processed_log/IMU/gyro/t"] = t_imu
    arrays["processed_log/IMU/gyro/value"] = np.column_stack(
        [np.zeros(n_imu), np.zeros(n_imu), np.full(n_imu, -0.01)]
    )
    arrays["processed_log/IMU/accelerometer/t"] = t_imu
    arrays["processed_log/IMU/accelerometer/value"] = np.column_stack(
        [np.full(n_imu, 0.1), np.zeros(n_imu), np.full(n_imu, -9.81)]
    )
    arrays["processed_log/CAN/wheel_speed/t"] = t_imu
    arrays["processed_log/CAN/wheel_speed/value"] = np.full((n_imu, 4), speed)
    rows, times = [], []
    for k in range(GNSS_EPOCHS):
        log_t = LOG0 + GNSS_STEP_S * k
        for n, prn in enumerate(SATELLITES):
            range_m = 2.1e7 + 1.0e6 * n + 100.0 * (log_t - LOG0)
            tow = TOW0 + (log_t - LOG0)
            rate = -300.0 + 100.0 * n
            rows.append([prn, WEEK, tow, np.nan, range_m, 5.0, rate, 0.1, 40.0 + n, range_m / 0.19])
            times.append(log_t)
    arrays["processed_log/GNSS/raw_gnss_ublox/t"] = np.array(times)
    arrays["processed_log/GNSS/raw_gnss_ublox/value"] = np.array(rows)
    return arrays


def segment_span_gps_s() -> tuple[float, float]:
    """First and last GPS time (s) of the segment's frames."""
    start = WEEK * SECONDS_PER_WEEK + TOW0
    return start, start + FRAME_STEP_S * (FRAMES - 1)


def write_segment(folder: Path, replaced: dict[str, bytes] | None = None) -> Path:
    """The synthetic segment in ``folder`` (created), with the arrays of ``replaced`` (relative
    path → file bytes) written instead of the good ones."""
    replaced = replaced or {}
    for relative, array in segment_arrays().items():
        path = folder / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(replaced.get(relative, npy_bytes(array)))
    return folder


def write_orbits(path: Path) -> Path:
    """An SP3 file of the segment's satellites covering it by an hour on each side."""
    start, _ = segment_span_gps_s()
    t = start - 3600.0 + 900.0 * np.arange(10)
    sats = [f"G{prn:02d}" for prn in SATELLITES]
    angle = np.linspace(0.0, 2.0, len(sats))
    unit = np.column_stack([np.cos(angle), np.sin(angle), np.full(len(sats), 0.5)])
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    position = np.broadcast_to(2.66e7 * unit, (t.size, len(sats), 3)).copy()
    path.write_text(sp3_text(t, sats, position, np.zeros((t.size, len(sats)))))
    return path
