"""``vo-doppler import comma2k19 SEGMENT --orbits SP3 -o SEQ``, ``vo-doppler import
kitti-raw DRIVE -o SEQ``, ``vo-doppler import smartloc CSV -o SEQ`` and ``vo-doppler import
rosbag BAG -o SEQ``: a recording in another layout → a standard sequence folder for
``vo-doppler run``."""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import add_yaw_rate_sign, number_in
from vo_doppler.commands.simulate_command import _origin as origin
from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.kitti_raw_import import KittiCamera, import_kitti_raw
from vo_doppler.io.rosbag_import import (
    AXES,
    RosbagOptions,
    RosClock,
    StampSource,
    import_rosbag,
    list_topics,
)
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
        choices=values(KittiCamera),
        default=KittiCamera.IMAGE_00.value,
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
    _register_rosbag(kinds)


def _register_rosbag(kinds) -> None:
    bag = kinds.add_parser(
        "rosbag",
        help="a ROS 1 .bag or a ROS 2 bag (sqlite3 or MCAP)",
        description="Write the images (sensor_msgs/Image as PNG, CompressedImage as sent) with "
        "their times, the calibration (CameraInfo, or --calib; the extrinsic from /tf_static), "
        "the yaw rate (sensor_msgs/Imu: the axis given or estimated from gravity, or with --dbc "
        "the yaw-rate signal of a can_msgs/Frame topic) and speed (TwistStamped or Odometry "
        "linear.x, or with --dbc the wheel-speed signals of a can_msgs/Frame topic), the forward "
        "acceleration, raw GNSS (gnss_comm "
        "GnssMeasMsg + GnssEphemMsg, or ublox_msgs RxmRAWX + RxmSFRBX) as RINEX observations "
        "and navigation, NavSatFix fixes (the origin), ground truth (--ground-truth) and "
        "sequence.yaml. Topics are found by type (--list-topics shows which) or named. ROS "
        "times go to GPS time by one offset (--clock); the GNSS epochs keep the receiver's "
        "GPS time; what was chosen is written under 'rosbag:' in sequence.yaml.",
    )
    bag.add_argument("bag", type=Path, help=".bag file, ROS 2 bag folder, .db3 or .mcap file")
    bag.add_argument("-o", "--output", type=Path, help="sequence folder")
    bag.add_argument(
        "--list-topics", action="store_true", help="list the topics and their use, then stop"
    )
    topics = bag.add_argument_group("topics (default: found by message type)")
    for name, what in (
        ("image", "sensor_msgs/Image or CompressedImage"),
        ("camera-info", "sensor_msgs/CameraInfo"),
        ("imu", "sensor_msgs/Imu"),
        ("speed", "TwistStamped, TwistWithCovarianceStamped or Odometry (linear.x)"),
        ("can", "can_msgs/Frame, decoded with --dbc"),
        ("gnss", "gnss_comm/GnssMeasMsg or ublox_msgs/RxmRAWX"),
        ("iono", "gnss_comm/StampedFloat64Array (Klobuchar α, β)"),
        ("fix", "sensor_msgs/NavSatFix"),
        ("tf", "tf2_msgs/TFMessage (default /tf_static)"),
    ):
        topics.add_argument(f"--{name}-topic", metavar="TOPIC", help=what)
    topics.add_argument(
        "--ephemeris-topic",
        action="append",
        metavar="TOPIC",
        help="GnssEphemMsg / GnssGloEphemMsg / RxmSFRBX (repeatable; default: those of the "
        "GNSS topic's interface)",
    )
    topics.add_argument(
        "--ground-truth",
        metavar="TOPIC",
        help="Odometry / PoseStamped (poses in the ENU frame of the origin) or NavSatFix: "
        "written as ground_truth.tum (never taken by default)",
    )
    can = bag.add_argument_group(
        "wheel speed and yaw rate from a CAN topic (instead of a speed topic and the IMU's gyro)"
    )
    can.add_argument(
        "--dbc", type=Path, metavar="FILE", help="DBC (or other cantools database) of the bus"
    )
    can.add_argument(
        "--wheel-speed",
        metavar="MSG.SIG[,MSG.SIG]",
        help="the DBC's wheel-speed signals, averaged (e.g. "
        "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR); the DBC unit is converted "
        "to m/s",
    )
    can.add_argument(
        "--yaw-rate",
        metavar="MSG.SIG",
        help="the DBC's yaw-rate signal (e.g. VEHICLE_DYNAMICS.YAW_RATE), counter-clockwise "
        "(turning left) positive after --yaw-rate-sign; the DBC unit (deg/s, rad/s) is "
        "converted to rad/s; the IMU, if any, then gives the forward acceleration only",
    )
    add_yaw_rate_sign(can)
    timing = bag.add_argument_group("time")
    timing.add_argument(
        "--stamps",
        choices=values(StampSource),
        default=StampSource.HEADER.value,
        help="message time: header.stamp, or the time the bag recorded it",
    )
    timing.add_argument(
        "--clock",
        choices=values(RosClock),
        default=RosClock.UTC.value,
        help="ROS time → GPS time: utc (ROS time is Unix UTC time, leap seconds added) or "
        "gnss (estimated from the raw GNSS messages' times)",
    )
    timing.add_argument(
        "--clock-offset",
        type=number_in(unit="s"),
        metavar="S",
        help="GPS − ROS time in seconds, instead of --clock",
    )
    frames = bag.add_argument_group("axes and frames")
    frames.add_argument(
        "--imu-yaw-axis",
        choices=("auto", *AXES),
        default="auto",
        help="the gyro axis pointing up (-z for a z-down IMU; auto: from gravity)",
    )
    frames.add_argument(
        "--imu-forward-axis",
        choices=("auto", "none", *AXES),
        default="auto",
        help="accelerometer axis along the vehicle's forward direction (auto: from the speed's "
        "change)",
    )
    frames.add_argument(
        "--origin",
        type=origin,
        help="LAT,LON,H of the ENU frame (default: the first NavSatFix fix)",
    )
    frames.add_argument(
        "--calib", type=Path, help="camera calibration file (instead of CameraInfo)"
    )
    frames.add_argument("--vehicle-frame", default="base_link", help="tf frame of the vehicle")
    frames.add_argument(
        "--gnss-frame", help="tf frame of the GNSS antenna (default: the NavSatFix frame_id)"
    )
    bag.add_check(lambda args: rosbag_options(args).problem())
    bag.set_defaults(func=run_rosbag, parser=bag)


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


def rosbag_options(args: argparse.Namespace) -> RosbagOptions:
    """The :class:`RosbagOptions` of the parsed ``import rosbag`` options."""
    return RosbagOptions(
        image_topic=args.image_topic,
        camera_info_topic=args.camera_info_topic,
        imu_topic=args.imu_topic,
        speed_topic=args.speed_topic,
        can_topic=args.can_topic,
        dbc=args.dbc,
        wheel_speed=args.wheel_speed,
        yaw_rate=args.yaw_rate,
        yaw_rate_sign=args.yaw_rate_sign,
        gnss_topic=args.gnss_topic,
        ephemeris_topics=tuple(args.ephemeris_topic) if args.ephemeris_topic else None,
        iono_topic=args.iono_topic,
        fix_topic=args.fix_topic,
        ground_truth_topic=args.ground_truth,
        tf_topic=args.tf_topic,
        stamps=args.stamps,
        clock=args.clock,
        clock_offset_s=args.clock_offset,
        imu_yaw_axis=args.imu_yaw_axis,
        imu_forward_axis=args.imu_forward_axis,
        origin=args.origin,
        calib=args.calib,
        vehicle_frame=args.vehicle_frame,
        gnss_frame=args.gnss_frame,
    )


def run_rosbag(args: argparse.Namespace) -> int:
    options = rosbag_options(args)
    if args.list_topics:
        sys.stdout.write("\n".join(list_topics(args.bag, options)) + "\n")
        return 0
    if args.output is None:
        args.parser.error("-o/--output is required (unless --list-topics)")
    summary = import_rosbag(args.bag, args.output, options)
    log.info(
        "wrote %s: %d images, %d GNSS epochs, %d ephemerides, %d yaw-rate samples (%s; IMU yaw "
        "axis %s), %d speed samples (%s), %d ground-truth poses; times: %s stamps, %s (GPS − ROS "
        "= %.3f s); camera extrinsic: %s",
        summary.folder,
        summary.images,
        summary.gnss_epochs,
        summary.ephemerides,
        summary.yaw_rate_samples,
        summary.yaw_rate_source,
        summary.yaw_axis,
        summary.speed_samples,
        summary.speed_source,
        summary.ground_truth_poses,
        summary.stamps,
        summary.clock,
        summary.gps_minus_ros_s,
        summary.extrinsic_from,
    )
    return 0
