"""``vo-doppler import comma2k19 SEGMENT --orbits SP3 -o SEQ``, ``vo-doppler import
kitti-raw DRIVE -o SEQ`` and ``vo-doppler import smartloc CSV -o SEQ``: a recording in another
layout → a standard sequence folder for ``vo-doppler run``."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.kitti_raw_import import CAMERAS as KITTI_CAMERAS
from vo_doppler.io.kitti_raw_import import import_kitti_raw
from vo_doppler.io.smartloc_import import import_smartloc

log = logging.getLogger(__name__)


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser("import", help=summary)
    kinds = parser.add_subparsers(dest="import_kind", metavar="KIND", required=True)
    comma = kinds.add_parser(
        "comma2k19",
        help="a comma2k19 segment folder (processed_log/, global_pose/)",
        description="Write RINEX 3 observations and per-row Doppler sigma from raw_gnss_ublox, "
        "the CAN log and DBC (without a DBC: the wheel speeds of processed_log/CAN and the IMU "
        "gyro's yaw rate), the IMU yaw rate and forward acceleration, global_pose as TUM ground "
        "truth on GPS time, the clock offsets and sequence.yaml. comma2k19 has no navigation "
        "file: give the day's precise orbits (SP3). A video.hevc in the segment is decoded into "
        "grey JPEG frames with the road camera's published intrinsics; without one the "
        "sequence has no camera.",
    )
    comma.add_argument("segment", type=Path, help="segment folder")
    comma.add_argument("--orbits", type=Path, required=True, help="SP3-c/d precise orbits")
    comma.add_argument("--clocks", type=Path, help="RINEX clock file")
    comma.add_argument(
        "--dbc",
        type=Path,
        help="DBC of the CAN log (default: the segment's "
        "toyota_2017_motion.dbc; without one, processed_log's wheel speeds and the IMU gyro)",
    )
    comma.add_argument("-o", "--output", type=Path, required=True, help="sequence folder")
    comma.set_defaults(func=run)
    kitti = kinds.add_parser(
        "kitti-raw",
        help="a KITTI raw drive folder (image_0N/, oxts/; the day's calib_*.txt beside it)",
        description="Write a camera's images with their times on GPS time (the timestamps "
        "read as UTC), its calibration from calib_cam_to_cam.txt (P_rect for a _sync drive, "
        "K and D for an _extract one; the extrinsic to the OXTS unit from calib_imu_to_velo "
        "and calib_velo_to_cam), OXTS wz and vf as the vehicle yaw rate and speed, the OXTS "
        "fixes as ENU ground truth (origin: the first fix) and sequence.yaml. A subsampled "
        "drive (timestamps.txt longer than data/) gives the frames that exist, with a "
        "warning. KITTI raw has no raw GNSS: run runs the VO and dead reckoning.",
    )
    kitti.add_argument("drive", type=Path, help="drive folder (YYYY_MM_DD_drive_NNNN_sync)")
    kitti.add_argument(
        "--camera",
        choices=KITTI_CAMERAS,
        default="image_00",
        help="the camera folder (image_00/01 grey, image_02/03 colour)",
    )
    kitti.add_argument("-o", "--output", type=Path, required=True, help="sequence folder")
    kitti.set_defaults(func=run_kitti_raw)
    smartloc = kinds.add_parser(
        "smartloc",
        help="a TU Chemnitz smartLoc raw CSV (';'-separated u-blox measurements + ground truth)",
        description="Write RINEX 3 observations of every measurement row (pseudorange, carrier, "
        "Doppler, C/N0; GLONASS channels from freqId), the Doppler sigma as range-rate sigma "
        "(wavelength x doStdev), the per-row NLOS label with each Doppler's range rate "
        "(gnss/doppler_nlos.csv), the ground truth's velocity and yaw rate as the vehicle "
        "signals, its positions and heading as ENU ground truth (origin: the first epoch) and "
        "sequence.yaml. smartLoc has no navigation file: without --nav the sequence has no gnss "
        "section and run runs the dead reckoning only; with the day's broadcast navigation "
        "(--nav) it runs the GNSS pipelines too. No images: no camera.",
    )
    smartloc.add_argument("csv", type=Path, help="smartLoc raw CSV (*_raw.csv)")
    smartloc.add_argument(
        "--nav",
        type=Path,
        action="append",
        default=[],
        help="RINEX navigation file of the recording's day (repeatable); copied into the "
        "sequence's gnss section",
    )
    smartloc.add_argument("-o", "--output", type=Path, required=True, help="sequence folder")
    smartloc.set_defaults(func=run_smartloc)


def run(args: argparse.Namespace) -> int:
    summary = import_comma2k19(args.segment, args.output, args.orbits, args.clocks, args.dbc)
    log.info(
        "wrote %s: %d GNSS epochs (%d rows, %d rows of other systems dropped), %d ground-truth "
        "poses, log clock + %.3f s = GPS time, yaw rate and wheel speed from %s%s",
        summary.folder,
        summary.gnss_epochs,
        summary.gnss_rows,
        summary.dropped_rows,
        summary.ground_truth_poses,
        summary.gps_minus_log_s,
        "the CAN log"
        if summary.vehicle_signals == "can"
        else "the IMU gyro and processed_log/CAN/wheel_speed",
        "; video decoded into the camera" if summary.has_video else "; no video: no camera",
    )
    return 0


def run_kitti_raw(args: argparse.Namespace) -> int:
    summary = import_kitti_raw(args.drive, args.output, args.camera)
    log.info(
        "wrote %s: %d images of %s (%d timestamps), %d OXTS rows (%d timestamps) as ENU ground "
        "truth, yaw rate and speed; %s images; extrinsic from %s; no GNSS: run runs the VO and "
        "dead reckoning",
        summary.folder,
        summary.images,
        summary.camera,
        summary.image_timestamps,
        summary.oxts_rows,
        summary.oxts_timestamps,
        "rectified" if summary.rectified else "raw (distorted)",
        summary.extrinsic_from,
    )
    return 0


def run_smartloc(args: argparse.Namespace) -> int:
    summary = import_smartloc(args.csv, args.output, args.nav)
    log.info(
        "wrote %s: %d measurement rows in %d epochs (NLOS %d, line of sight %d, unlabelled %d), "
        "%d ground-truth poses, vehicle speed and yaw rate from the ground truth; %s",
        summary.folder,
        summary.rows,
        summary.epochs,
        summary.nlos,
        summary.line_of_sight,
        summary.unlabelled,
        summary.ground_truth_poses,
        f"navigation {', '.join(p.name for p in summary.navigation)}: run runs the GNSS pipelines"
        if summary.navigation
        else "no navigation file (smartLoc ships none): no gnss section, run runs the dead "
        "reckoning only; import again with --nav for the GNSS pipelines",
    )
    for problem in summary.problems:
        log.warning("%s", problem)
    return 0
