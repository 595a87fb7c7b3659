"""``vo-doppler import comma2k19 SEGMENT --orbits SP3 -o SEQ``: a recording in another layout
→ a standard sequence folder for ``vo-doppler run``."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from vo_doppler.io.comma2k19_import import import_comma2k19

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
