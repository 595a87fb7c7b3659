"""A comma2k19 segment → a standard sequence folder (``sequence.yaml``, format
``vo-doppler-sequence/1``, docs/sequence_format.md) that ``vo-doppler run`` reads.

Written: ``gnss/raw_gnss_ublox.obs`` (RINEX 3.04, GPS + GLONASS: C1C L1C D1C S1C; the Doppler
D = −ṙ/λ from the pseudorange rate ṙ, RINEX 3.05 sec. 5.2.10), ``gnss/doppler_sigma.csv`` (the
receiver's σ of each pseudorange rate, ``gnss.doppler_sigma``), the precise orbits (and clocks)
copied beside them, ``can/`` (the segment's ``can_motion.log``, or one written from ``raw_can``
in candump format, with the DBC; the CAN yaw rate and the four wheel speeds), or, for a segment
without a DBC (comma2k19 ships none; the example segment of ../shared has its Toyota's),
``vehicle/wheel_speed.csv`` from the wheel speeds comma decoded
(``processed_log/CAN/wheel_speed``, every car of the dataset) with the IMU gyro as the yaw
rate; ``imu/yaw_rate.csv`` (gyro yaw rate on the log clock), ``ground_truth.tum``
(``global_pose`` as vehicle poses in the ENU frame of the first pose) and the clock offsets.
Every log-clock time (CAN, IMU, the poses' and the video's ``frame_times``) goes to GPS time
through one offset, the GNSS receiver's time tags against their log times
(``comma2k19.gps_minus_log``; ``global_pose``'s own ``frame_gps_times``, 0.126 s later on the
example segment, are recorded but not used). A segment's ``video.hevc`` is decoded into the
camera (``vo_doppler.io.comma2k19_video``); without one the camera section is left out, and
``run`` then runs the non-visual pipelines.
"""

from __future__ import annotations

import logging
import shutil
from dataclasses import dataclass
from pathlib import Path

import can
import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from vo_doppler.bounds import GPS_TIME
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT, EnuFrame, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.io.can import check_dbc
from vo_doppler.io.comma2k19 import (
    RAW_GNSS,
    gps_minus_log,
    gps_minus_mono,
    load_array,
    numeric_array,
    read_forward_acceleration,
    read_gyro_yaw_rate,
    read_pose_arrays,
    read_raw_gnss,
    read_vehicle_poses,
    read_wheel_speed,
)
from vo_doppler.io.comma2k19_video import CALIB, IMAGES, TIMES, VIDEO, decode_video
from vo_doppler.io.doppler_sigma import write_doppler_sigma
from vo_doppler.io.output_folder import check_output_folder, open_output_folder
from vo_doppler.io.rinex_write import ObsEpochs, write_obs
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.io.sensor_csv import (
    FORWARD_ACCELERATION_COLUMN,
    SPEED_COLUMN,
    YAW_RATE_COLUMN,
    write_sensor_csv,
)
from vo_doppler.io.sequence import FORMAT, MANIFEST, origin_entry
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gpstime import SECONDS_PER_WEEK
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

GPS_L1_HZ = 1575.42e6
GLONASS_G1_HZ = (1602.0e6, 0.5625e6)
"""ICD-GLONASS 5.1 sec. 3.3.1.4: G1 = 1602 + 0.5625·k MHz for channel k."""
CODES = ("C1C", "L1C", "D1C", "S1C")
CAN_LOG = "can_motion.log"
DBC = "toyota_2017_motion.dbc"
YAW_RATE_SIGNAL = "KINEMATICS.YAW_RATE"
WHEEL_SIGNALS = ",".join(f"WHEEL_SPEEDS.WHEEL_SPEED_{w}" for w in ("FL", "FR", "RL", "RR"))


@dataclass(frozen=True)
class ImportSummary:
    folder: Path
    gnss_epochs: int
    gnss_rows: int
    dropped_rows: int
    gps_minus_log_s: float
    ground_truth_poses: int
    has_video: bool
    vehicle_signals: str
    """``can`` (the CAN log decoded by its DBC) or ``vehicle`` (without a DBC: the wheel speeds
    comma decoded, ``processed_log/CAN/wheel_speed``, and the IMU gyro's yaw rate)."""


def import_comma2k19(
    segment: str | Path,
    output: str | Path,
    orbits: str | Path,
    clocks: str | Path | None = None,
    dbc: str | Path | None = None,
) -> ImportSummary:
    """Write the sequence folder ``output`` from the segment folder ``segment`` (checked first:
    new, empty or an earlier import's, and none of the inputs inside it).

    The orbits (and clocks) and the DBC are read first, with the readers ``run`` uses, so that
    a file ``run`` would refuse stops the import before anything is written."""
    segment, output = Path(segment), Path(output)
    check_output_folder(output, "import", [segment, orbits, clocks, dbc])
    if dbc is not None and not Path(dbc).is_file():
        raise InputError("the DBC for the CAN log is not a file", dbc)
    dbc = Path(dbc) if dbc is not None else segment / DBC
    if not dbc.is_file():
        log.info(
            "%s: no DBC (%s); the wheel speed comes from processed_log/CAN/wheel_speed and the "
            "yaw rate from the IMU gyro",
            segment,
            DBC,
        )
        dbc = None
    else:
        check_dbc(dbc, YAW_RATE_SIGNAL, WHEEL_SIGNALS)
    _check_orbits(segment, Path(orbits), clocks)
    open_output_folder(output, "import")
    for folder in ("gnss", "imu", "can" if dbc else "vehicle"):
        (output / folder).mkdir(parents=True, exist_ok=True)
    offset = gps_minus_log(segment)
    pose_offset = gps_minus_mono(segment)
    raw = read_raw_gnss(segment)
    if raw.t.size == 0:
        raise InputError(
            f"no usable GPS or GLONASS measurement ({raw.n_dropped} rows dropped)",
            segment.joinpath(*RAW_GNSS, "value"),
        )
    t_pose, ecef, vehicle_to_ecef, mount = read_vehicle_poses(segment)
    late = GPS_TIME.outside(t_pose + offset)
    if late.any():
        row = int(np.flatnonzero(late)[0])
        raise InputError(
            f"row {row}: frame time {t_pose[row]:g} s is GPS time {t_pose[row] + offset:g} s "
            f"through the receiver's clock offset {offset:g} s, outside {GPS_TIME} (1980-2100)",
            segment / "global_pose" / "frame_times",
        )
    lat, lon, height = (float(v) for v in ecef_to_geodetic(ecef[0]))
    epochs, obs_rows = _write_gnss(output / "gnss", raw, ecef[0])
    gnss = {
        "obs": "gnss/raw_gnss_ublox.obs",
        "orbits": f"gnss/{Path(orbits).name}",
        "doppler_sigma": "gnss/doppler_sigma.csv",
    }
    shutil.copyfile(orbits, output / gnss["orbits"])
    if clocks is not None:
        gnss["clocks"] = f"gnss/{Path(clocks).name}"
        shutil.copyfile(clocks, output / gnss["clocks"])
    t_gyro, yaw_rate = read_gyro_yaw_rate(segment)
    write_sensor_csv(
        output / "imu" / "yaw_rate.csv", SensorSeries(t_gyro, yaw_rate), YAW_RATE_COLUMN
    )
    if dbc is not None:
        _write_can(segment, output / "can" / CAN_LOG)
        shutil.copyfile(dbc, output / "can" / dbc.name)
        vehicle = {
            "can": {
                "log": f"can/{CAN_LOG}",
                "dbc": f"can/{dbc.name}",
                "yaw_rate": YAW_RATE_SIGNAL,
                "wheel_speed": WHEEL_SIGNALS,
                "time_offset_s": offset,
            }
        }
    else:
        t_wheel, wheel_speed = read_wheel_speed(segment)
        write_sensor_csv(
            output / "vehicle" / "wheel_speed.csv",
            SensorSeries(t_wheel, wheel_speed),
            SPEED_COLUMN,
        )
        vehicle = {
            "vehicle": {
                "yaw_rate": "imu/yaw_rate.csv",
                "wheel_speed": "vehicle/wheel_speed.csv",
                "time_offset_s": offset,
            }
        }
    t_acc, forward = read_forward_acceleration(segment)
    write_sensor_csv(
        output / "imu" / "forward_acceleration.csv",
        SensorSeries(t_acc, forward),
        FORWARD_ACCELERATION_COLUMN,
    )
    rotation = ecef_to_enu_rotation(lat, lon)
    truth = Trajectory(
        t_pose + offset,
        (ecef - ecef[0]) @ rotation.T,
        Rotation.from_matrix(np.einsum("ij,njk->nik", rotation, vehicle_to_ecef)),
    )
    write_tum(output / "ground_truth.tum", truth)
    has_video = (segment / VIDEO).is_file()
    camera = {}
    if has_video:
        decode_video(segment / VIDEO, t_pose, output, mount)
        camera = {"images": IMAGES, "times": TIMES, "calib": CALIB, "time_offset_s": offset}
    manifest = {
        "format": FORMAT,
        "name": segment.name,
        "source": f"comma2k19 segment {segment} (vo-doppler import comma2k19)",
        "origin": origin_entry(EnuFrame(lat, lon, height)),
        **({"camera": camera} if camera else {}),
        "gnss": gnss,
        **vehicle,
        "imu": {
            "yaw_rate": "imu/yaw_rate.csv",
            "forward_acceleration": "imu/forward_acceleration.csv",
            "time_offset_s": offset,
        },
        "ground_truth": {
            "trajectory": "ground_truth.tum",
            "device_mount_yaw_deg": float(np.degrees(mount.yaw)),
            "device_mount_pitch_deg": float(np.degrees(mount.pitch)),
            "device_mount_roll_deg": float(np.degrees(mount.roll)),
        },
        "clock_offsets": {
            "log_to_gps_s": offset,
            "from": "raw_gnss_ublox receiver time tags minus log times",
            "global_pose_frame_gps_times_minus_log_s": pose_offset,
        },
    }
    (output / MANIFEST).write_text(yaml.safe_dump(manifest, sort_keys=False))
    return ImportSummary(
        output,
        epochs,
        obs_rows,
        raw.n_dropped,
        offset,
        len(truth),
        has_video,
        "can" if dbc is not None else "vehicle",
    )


def _write_gnss(folder: Path, raw, approx_position: np.ndarray) -> tuple[int, int]:
    """RINEX observations and the σ table; returns (epochs, rows)."""
    epoch_time, epoch = np.unique(np.round(raw.t, 3), return_inverse=True)
    satellite = np.char.add(raw.system, np.char.zfill(raw.prn.astype(str), 2))
    glonass = raw.system == "R"
    frequency = np.where(
        glonass, GLONASS_G1_HZ[0] + GLONASS_G1_HZ[1] * np.nan_to_num(raw.glonass_channel), GPS_L1_HZ
    )
    doppler_hz = -raw.range_rate * frequency / SPEED_OF_LIGHT
    values = np.column_stack([raw.pseudorange, raw.carrier_phase, doppler_hz, raw.cn0])
    channels = {
        int(p): int(k)
        for p, k in zip(raw.prn[glonass], raw.glonass_channel[glonass], strict=True)
        if np.isfinite(k)
    }
    write_obs(
        folder / "raw_gnss_ublox.obs",
        ObsEpochs(epoch_time, epoch, satellite, values, CODES),
        approx_position,
        float(np.median(np.diff(epoch_time))) if epoch_time.size > 1 else 0.0,
        marker_name="COMMA2K19",
        receiver="U-BLOX M8",
        glonass_channels=channels,
    )
    write_doppler_sigma(
        folder / "doppler_sigma.csv",
        ReportedSigma(
            epoch_time[epoch], satellite, np.full(satellite.size, "D1C"), raw.range_rate_sigma
        ),
    )
    return int(epoch_time.size), int(satellite.size)


def _write_can(segment: Path, target: Path) -> None:
    """The segment's candump log, or one written from ``processed_log/CAN/raw_can`` (payloads
    stored as numpy ``S8`` lose trailing zero bytes: padded back to 8)."""
    if (segment / CAN_LOG).is_file():
        shutil.copyfile(segment / CAN_LOG, target)
        return
    t, address, data, source = _raw_can_arrays(segment)
    with can.CanutilsLogWriter(str(target), channel="can0") as writer:
        for k in np.flatnonzero(source == 0):
            payload = bytes(data[k]).ljust(8, b"\0")
            writer.on_message_received(
                can.Message(
                    timestamp=float(t[k]),
                    arbitration_id=int(address[k]),
                    data=payload,
                    is_extended_id=bool(address[k] > MAX_STANDARD_ID),
                    channel="can0",
                )
            )


MAX_STANDARD_ID, MAX_EXTENDED_ID = 0x7FF, 0x1FFFFFFF
"""Largest 11-bit and 29-bit CAN identifiers."""
RAW_CAN = ("processed_log", "CAN", "raw_can")


def _raw_can_arrays(segment: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``raw_can``'s times, identifiers, payloads (bytes, at most 8) and bus numbers, one row
    each; an :class:`InputError` names the array file that is not."""
    folder = segment.joinpath(*RAW_CAN)
    t = numeric_array(segment, *RAW_CAN, "t")
    address = numeric_array(segment, *RAW_CAN, "address")
    source = numeric_array(segment, *RAW_CAN, "src")
    data = load_array(segment, *RAW_CAN, "data")
    if data.dtype.kind != "S" or data.dtype.itemsize > 8 or data.ndim != 1:
        raise InputError(
            f"array of shape {data.shape} and type {data.dtype}, expected (N,) of bytes (|S8)",
            folder / "data",
        )
    for name, array in (("address", address), ("data", data), ("src", source)):
        if array.shape[0] != t.size:
            raise InputError(f"{array.shape[0]} rows for {t.size} times", folder / name)
    wrong = (address != np.round(address)) | (address < 0) | (address > MAX_EXTENDED_ID)
    if wrong.any():
        row = int(np.flatnonzero(wrong)[0])
        raise InputError(f"row {row}: {address[row]:g} is not a CAN identifier", folder / "address")
    wild = GPS_TIME.outside(np.abs(t))
    if wild.any():
        row = int(np.flatnonzero(wild)[0])
        raise InputError(f"row {row}: time {t[row]:g} s is beyond any clock", folder / "t")
    return t, address.astype(np.int64), data, source


def segment_gps_span(segment: str | Path) -> tuple[float, float]:
    """First and last GPS time (s) of the segment's ``global_pose`` frames."""
    gps_times = read_pose_arrays(segment).gps_times
    t = gps_times[:, 0] * SECONDS_PER_WEEK + gps_times[:, 1]
    return float(t.min()), float(t.max())


def _uncovered(segment: Path, start: float, end: float) -> str:
    """The segment and its GPS span, for an error about orbits that do not cover it."""
    return (
        f"the segment {segment} (GPS week {int(start // SECONDS_PER_WEEK)}, seconds of week "
        f"{start % SECONDS_PER_WEEK:.0f}–{end % SECONDS_PER_WEEK:.0f})"
    )


def _check_orbits(segment: Path, orbits: Path, clocks: str | Path | None) -> None:
    """Read the orbits (and clocks) as ``run`` will and check that they cover the segment."""
    product = read_satellite_states(orbits=orbits, clocks=None if clocks is None else Path(clocks))
    start, end = segment_gps_span(segment)
    if min(start - product.t[0], product.t[-1] - end) < 0:
        raise InputError(f"the orbits do not cover {_uncovered(segment, start, end)}", orbits)


def orbits_for_segment(segment: str | Path, orbits: str | Path) -> Path:
    """``orbits`` if it is a file; for a folder, its SP3 file (``*.sp3``, any case) whose epochs
    reach furthest beyond the segment on both sides (the interpolation needs epochs around it)."""
    orbits = Path(orbits)
    if not orbits.is_dir():
        return orbits
    start, end = segment_gps_span(segment)
    margins = {}
    for path in sorted(p for p in orbits.iterdir() if p.suffix.lower() == ".sp3"):
        product = read_sp3(path)
        margins[path] = min(start - product.t[0], product.t[-1] - end)
    if not margins:
        raise InputError("no SP3 files (*.sp3) in the orbits folder", orbits)
    best = max(margins, key=margins.get)
    if margins[best] < 0:
        raise InputError(f"no SP3 file covers {_uncovered(segment, start, end)}", orbits)
    return best


@dataclass(frozen=True)
class Comma2k19Import:
    """The ``prepare`` step of a batch over raw comma2k19 segments (``vo_doppler.batch``):
    imports ``segment`` into ``work_dir`` (emptied first) and returns it."""

    orbits: Path
    dbc: Path | None = None

    def __call__(self, segment: Path, work_dir: Path) -> Path:
        shutil.rmtree(work_dir, ignore_errors=True)
        orbits = orbits_for_segment(segment, self.orbits)
        import_comma2k19(segment, work_dir, orbits, None, self.dbc)
        return work_dir
