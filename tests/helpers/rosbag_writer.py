"""A sequence folder → a ROS bag, with rosbags' writers: the test input of the ROS bag importer;
and :class:`SmallBag`, the writer it uses, for tests that build their own topics (CAN frames,
GLONASS ephemerides).

Topics (ROS times are the GPS times as Unix UTC times: GPS − 315964800 s − the leap seconds):

- ``/camera/image_raw`` (sensor_msgs/Image, mono8) or ``/camera/image_raw/compressed``
  (CompressedImage, the image file's bytes) with ``/camera/camera_info`` and ``/tf_static``
  (``base_link`` → ``camera``: the calibration's ``T_vehicle_camera``; ``base_link`` →
  ``gps``: the GNSS antenna lever arm, the frame of ``/fix``);
- ``/imu/data`` (Imu: angular_velocity.z = the yaw rate, linear_acceleration = (forward
  acceleration, 0, +g)) at the yaw-rate samples; ``/vehicle/twist`` (TwistStamped, linear.x =
  the wheel speed);
- raw GNSS, ``gnss_comm`` (``/gnss/meas`` GnssMeasMsg per epoch, ``/gnss/ephem`` GnssEphemMsg,
  ``/gnss/iono`` StampedFloat64Array) or ``ublox_msgs`` (``/ublox/rxmraw`` RxmRAWX per epoch,
  ``/ublox/rxmsfrb`` RxmSFRBX: GPS LNAV subframes 1–3 of each GPS ephemeris, Galileo I/NAV
  words 1–5 of each Galileo one, GLONASS strings 1–4 of each GLONASS one); a GNSS message's
  receive time is its epoch + ``GNSS_LATENCY_S``;
- ``/fix`` (NavSatFix of the GNSS antenna on the ground truth, every 10th pose: its first is
  the simulator's RINEX approximate position) and ``/ground_truth`` (Odometry in the ENU frame
  of the origin).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from scipy.spatial.transform import Rotation

from tests.helpers.galileo_inav import encode_ephemeris as galileo_words
from tests.helpers.galileo_inav import sfrbx_words as galileo_page
from tests.helpers.glonass_strings import encode_strings, sfrbx_words
from tests.helpers.lnav import encode_ephemeris, with_parity
from vo_doppler.geo import ecef_to_geodetic
from vo_doppler.io.gps_lnav import URA_METERS
from vo_doppler.io.rosbag_gnss import carrier_hz, satellite_number
from vo_doppler.io.rosbag_types import typestore
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, UNIX_TIME_AT_GPS_EPOCH_S, gps_minus_utc

GNSS_LATENCY_S = 0.05
GRAVITY = 9.80665
UBX_GNSS_ID = {"G": 0, "S": 1, "E": 2, "C": 3, "J": 5, "R": 6}


def ros_ns(gps: float) -> int:
    """ROS time (Unix UTC, ns) of a GPS time, whole seconds added as integers (exact to 1 ns
    of the float64 value)."""
    whole = int(np.floor(gps))
    seconds = whole + int(UNIX_TIME_AT_GPS_EPOCH_S) - int(gps_minus_utc(gps))
    return seconds * 1_000_000_000 + round((gps - whole) * 1e9)


def bag_path(folder: Path, flavour: str, name: str) -> Path:
    """A ``.bag`` file for ROS 1, a bag folder for ``sqlite3`` / ``mcap``."""
    return folder / (f"{name}.bag" if flavour == "ros1" else f"{name}_{flavour}")


class SmallBag:
    """One bag being written (a context manager); ``types`` are the message classes."""

    def __init__(self, path: Path, flavour: str) -> None:
        self.ros2 = flavour != "ros1"
        self.store = typestore(self.ros2)
        self.types = self.store.types
        if self.ros2:
            plugin = StoragePlugin.MCAP if flavour == "mcap" else StoragePlugin.SQLITE3
            self.writer = Writer2(path, version=9, storage_plugin=plugin)
        else:
            self.writer = Writer1(path)
        self.connections: dict[str, object] = {}

    def __enter__(self) -> SmallBag:
        self.writer.open()
        return self

    def __exit__(self, *exc_info) -> None:
        self.writer.close()

    def write(self, topic: str, msgtype: str, t_ns: int, message) -> None:
        if topic not in self.connections:
            self.connections[topic] = self.writer.add_connection(
                topic, msgtype, typestore=self.store
            )
        if self.ros2:
            raw = self.store.serialize_cdr(message, msgtype)
        else:
            raw = self.store.serialize_ros1(message, msgtype)
        self.writer.write(self.connections[topic], t_ns, raw)

    def header(self, t_ns: int, frame: str = ""):
        stamp = self.types["builtin_interfaces/msg/Time"](
            sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000
        )
        Header = self.types["std_msgs/msg/Header"]
        if self.ros2:
            return Header(stamp=stamp, frame_id=frame)
        return Header(seq=0, stamp=stamp, frame_id=frame)

    def imu(self, gps_times, yaw_rate, forward=0.0) -> None:
        """``/imu/data`` at each GPS time: angular_velocity.z = the yaw rate, linear_acceleration
        = (the forward acceleration, 0, +g): an IMU with z up and x forward."""
        zeros = np.zeros(9)
        still = np.array([0.0, 0.0, 0.0, 1.0])
        n = len(gps_times)
        for t_gps, rate, ahead in zip(
            gps_times, np.broadcast_to(yaw_rate, n), np.broadcast_to(forward, n), strict=True
        ):
            t = ros_ns(float(t_gps))
            message = self.types["sensor_msgs/msg/Imu"](
                header=self.header(t, "imu"),
                orientation=_quat(self, still),
                orientation_covariance=np.r_[-1.0, zeros[1:]],
                angular_velocity=_vec(self, 0.0, 0.0, rate),
                angular_velocity_covariance=zeros,
                linear_acceleration=_vec(self, ahead, 0.0, GRAVITY),
                linear_acceleration_covariance=zeros,
            )
            self.write("/imu/data", "sensor_msgs/msg/Imu", t, message)

    def twist(self, gps_times, speed) -> None:
        """``/vehicle/twist`` (TwistStamped, linear.x = the speed) at each GPS time."""
        for t_gps, v in zip(gps_times, np.broadcast_to(speed, len(gps_times)), strict=True):
            t = ros_ns(float(t_gps))
            twist = self.types["geometry_msgs/msg/Twist"](
                linear=_vec(self, v, 0.0, 0.0), angular=_vec(self, 0.0, 0.0, 0.0)
            )
            message = self.types["geometry_msgs/msg/TwistStamped"](
                header=self.header(t, "base_link"), twist=twist
            )
            self.write("/vehicle/twist", "geometry_msgs/msg/TwistStamped", t, message)

    def can_frame(self, topic: str, t_ns: int, fields: dict) -> None:
        """One ``can_msgs/Frame`` of :func:`frame_fields` (edited or not)."""
        self.write(topic, "can_msgs/msg/Frame", t_ns, self.types["can_msgs/msg/Frame"](**fields))


def frame_fields(bag: SmallBag, t_ns: int, frame_id: int, data: bytes, **flags) -> dict:
    """The fields of a ``can_msgs/Frame`` of ``data`` (dlc its length, zero-padded to 8);
    ``flags``: ``is_extended``, ``is_rtr``, ``is_error`` (default false)."""
    return {
        "header": bag.header(t_ns),
        "id": frame_id,
        "is_rtr": flags.get("is_rtr", False),
        "is_extended": flags.get("is_extended", False),
        "is_error": flags.get("is_error", False),
        "dlc": len(data),
        "data": np.frombuffer(data.ljust(8, b"\0"), np.uint8).copy(),
    }


def _vec(out: SmallBag, x: float, y: float, z: float):
    return out.types["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))


def _quat(out: SmallBag, q: np.ndarray):
    return out.types["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])


def write_bag(
    sequence_folder: Path,
    bag: Path,
    flavour: str = "ros1",
    gnss: str = "gnss_comm",
    compressed: bool = False,
) -> Path:
    """Write ``bag`` (a ``.bag`` file for ROS 1, a folder for ``sqlite3``/``mcap``)."""
    return write_sequence_bag(read_sequence(sequence_folder), bag, flavour, gnss, compressed)


def write_sequence_bag(
    seq, bag: Path, flavour: str = "ros1", gnss: str = "gnss_comm", compressed: bool = False
) -> Path:
    """:func:`write_bag` of a :class:`~vo_doppler.model.sequence.Sequence` already read."""
    with SmallBag(bag, flavour) as out:
        _camera(out, seq, compressed)
        _vehicle(out, seq)
        if gnss == "gnss_comm":
            _gnss_comm(out, seq)
        else:
            _ublox(out, seq)
        _truth(out, seq)
    return bag


def _camera(out: SmallBag, seq, compressed: bool) -> None:
    import cv2

    cam = seq.camera
    info = out.types["sensor_msgs/msg/CameraInfo"]
    roi = out.types["sensor_msgs/msg/RegionOfInterest"](
        x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
    )
    K = np.array([cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1], dtype=float)
    P = np.array([cam.fx, 0, cam.cx, 0, 0, cam.fy, cam.cy, 0, 0, 0, 1, 0], dtype=float)
    t0 = ros_ns(float(seq.image_times[0]))
    names = ("d", "k", "r", "p") if out.ros2 else ("D", "K", "R", "P")
    arrays = dict(
        zip(names, (np.asarray(cam.distortion, float), K, np.eye(3).ravel(), P), strict=True)
    )
    out.write(
        "/camera/camera_info",
        "sensor_msgs/msg/CameraInfo",
        t0,
        info(
            header=out.header(t0, "camera"),
            height=cam.height,
            width=cam.width,
            distortion_model="plumb_bob",
            binning_x=0,
            binning_y=0,
            roi=roi,
            **arrays,
        ),
    )
    T = cam.T_vehicle_camera
    TransformStamped = out.types["geometry_msgs/msg/TransformStamped"]
    Transform = out.types["geometry_msgs/msg/Transform"]
    tf = TransformStamped(
        header=out.header(t0, "base_link"),
        child_frame_id="camera",
        transform=Transform(
            translation=_vec(out, *T[:3, 3]),
            rotation=_quat(out, Rotation.from_matrix(T[:3, :3]).as_quat()),
        ),
    )
    antenna = TransformStamped(
        header=out.header(t0, "base_link"),
        child_frame_id="gps",
        transform=Transform(
            translation=_vec(out, *seq.antenna_lever_arm_m),
            rotation=_quat(out, np.array([0.0, 0.0, 0.0, 1.0])),
        ),
    )
    out.write(
        "/tf_static",
        "tf2_msgs/msg/TFMessage",
        t0,
        out.types["tf2_msgs/msg/TFMessage"](transforms=[tf, antenna]),
    )
    for path, gps in zip(seq.image_paths, seq.image_times, strict=True):
        t = ros_ns(float(gps))
        if compressed:
            data = np.frombuffer(path.read_bytes(), np.uint8)
            message = out.types["sensor_msgs/msg/CompressedImage"](
                header=out.header(t, "camera"), format=path.suffix.lstrip("."), data=data
            )
            out.write("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage", t, message)
            continue
        pixels = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        message = out.types["sensor_msgs/msg/Image"](
            header=out.header(t, "camera"),
            height=pixels.shape[0],
            width=pixels.shape[1],
            encoding="mono8",
            is_bigendian=0,
            step=pixels.shape[1],
            data=pixels.ravel(),
        )
        out.write("/camera/image_raw", "sensor_msgs/msg/Image", t, message)


def _vehicle(out: SmallBag, seq) -> None:
    yaw = seq.yaw_rate
    accel = seq.forward_acceleration
    forward = np.interp(yaw.t, accel.t, accel.value) if accel is not None else 0.0
    out.imu(yaw.t, yaw.value, forward)
    out.twist(seq.wheel_speed.t, seq.wheel_speed.value)


def _epochs(obs):
    """(epoch time, [(system, prn, {code: value})]) per epoch."""
    sats = obs.satellites()
    for t in obs.epoch_time:
        rows = np.flatnonzero(obs.time == t)
        per: dict[str, dict[str, float]] = {}
        for r in rows:
            per.setdefault(str(sats[r]), {})[obs.codes[obs.code[r]]] = float(obs.value[r])
        yield float(t), [(s[0], int(s[1:]), v) for s, v in sorted(per.items())]


def _gnss_time(out: SmallBag, t: float):
    week = int(t // SECONDS_PER_WEEK)
    return out.types["gnss_comm/msg/GnssTimeMsg"](week=week, tow=t - week * SECONDS_PER_WEEK)


def _gnss_comm(out: SmallBag, seq) -> None:
    GnssObsMsg = out.types["gnss_comm/msg/GnssObsMsg"]
    GnssMeasMsg = out.types["gnss_comm/msg/GnssMeasMsg"]
    for t, sats in _epochs(seq.observations):
        meas = []
        for system, prn, values in sats:
            signals = sorted({code[1:] for code in values})
            arrays: dict[str, list[float]] = {k: [] for k in ("freqs", "CN0", "psr", "cp", "dopp")}
            for signal in signals:
                arrays["freqs"].append(carrier_hz(system, signal[0]))
                arrays["psr"].append(values.get("C" + signal, 0.0))
                arrays["cp"].append(values.get("L" + signal, 0.0))
                arrays["dopp"].append(values.get("D" + signal, np.nan))
                arrays["CN0"].append(values.get("S" + signal, 0.0))
            n = len(signals)
            meas.append(
                GnssObsMsg(
                    time=_gnss_time(out, t),
                    sat=satellite_number(system, prn),
                    freqs=np.array(arrays["freqs"]),
                    CN0=np.array(arrays["CN0"]),
                    LLI=np.zeros(n, np.uint8),
                    code=np.full(n, 1 if signals[0] == "1C" else 0, np.uint8),
                    psr=np.array(arrays["psr"]),
                    psr_std=np.zeros(n),
                    cp=np.array(arrays["cp"]),
                    cp_std=np.zeros(n),
                    dopp=np.array(arrays["dopp"]),
                    dopp_std=np.zeros(n),
                    status=np.ones(n, np.uint8),
                )
            )
        out.write(
            "/gnss/meas",
            "gnss_comm/msg/GnssMeasMsg",
            ros_ns(t + GNSS_LATENCY_S),
            GnssMeasMsg(meas=meas),
        )
    nav = seq.navigation
    if hasattr(nav, "kepler"):
        _gnss_comm_ephemerides(out, nav)


def _gnss_comm_ephemerides(out: SmallBag, nav) -> None:
    Ephem = out.types["gnss_comm/msg/GnssEphemMsg"]
    kepler = nav.kepler
    for k in range(len(kepler)):
        system, prn = str(kepler.system[k]), int(kepler.prn[k])
        p = {name: float(values[k]) for name, values in kepler.params.items()}
        toc = float(kepler.toc[k])
        galileo_or_bds = system in "EC"
        ephem = Ephem(
            sat=satellite_number(system, prn),
            ttr=_gnss_time(out, toc - toc % SECONDS_PER_WEEK + p["transmission_sow"]),
            toe=_gnss_time(out, p["toe"]),
            toc=_gnss_time(out, toc),
            toe_tow=p["toe_sow"],
            week=int(p["week"]),
            iode=int(p["iode"]),
            iodc=int(p["fit_interval"] if system == "C" else (0 if galileo_or_bds else p["iodc"])),
            health=int(p["health"]),
            code=int(p["codes"]),
            ura=p["accuracy"],
            A=p["sqrt_a"] ** 2,
            e=p["e"],
            i0=p["i0"],
            omg=p["omega"],
            OMG0=p["omega0"],
            M0=p["m0"],
            delta_n=p["delta_n"],
            OMG_dot=p["omega_dot"],
            i_dot=p["idot"],
            cuc=p["cuc"],
            cus=p["cus"],
            crc=p["crc"],
            crs=p["crs"],
            cic=p["cic"],
            cis=p["cis"],
            af0=p["af0"],
            af1=p["af1"],
            af2=p["af2"],
            tgd0=p["tgd"],
            tgd1=p["iodc"] if galileo_or_bds else 0.0,
            A_dot=0.0,
            n_dot=0.0,
        )
        out.write("/gnss/ephem", "gnss_comm/msg/GnssEphemMsg", ros_ns(toc), ephem)
    if nav.klobuchar is not None:
        Array = out.types["gnss_comm/msg/StampedFloat64Array"]
        t = ros_ns(float(kepler.toc.min()))
        out.write(
            "/gnss/iono",
            "gnss_comm/msg/StampedFloat64Array",
            t,
            Array(header=out.header(t), data=np.asarray(nav.klobuchar, float)),
        )


ROS2_UBLOX_NAMES = {
    "prMes": "pr_mes",
    "cpMes": "cp_mes",
    "doMes": "do_mes",
    "gnssId": "gnss_id",
    "svId": "sv_id",
    "sigId": "sig_id",
    "freqId": "freq_id",
    "prStdev": "pr_stdev",
    "cpStdev": "cp_stdev",
    "doStdev": "do_stdev",
    "trkStat": "trk_stat",
    "reserved3": "reserved1",
    "rcvTOW": "rcv_tow",
    "leapS": "leap_s",
    "numMeas": "num_meas",
    "recStat": "rec_stat",
    "numWords": "num_words",
}
"""ublox_msgs' ROS 1 field names → its ROS 2 ones."""


def _ublox_fields(out: SmallBag, fields: dict) -> dict:
    return {ROS2_UBLOX_NAMES.get(k, k): v for k, v in fields.items()} if out.ros2 else fields


def ublox_rawx(out: SmallBag, t: float, measurements: list[dict]) -> None:
    """One ``/ublox/rxmraw`` RxmRAWX of epoch ``t`` (GPS) received ``GNSS_LATENCY_S`` later;
    ``measurements``: RxmRAWX_Meas fields by their ROS 1 names."""
    ros2 = out.ros2
    Meas = out.types["ublox_msgs/msg/RxmRAWXMeas" if ros2 else "ublox_msgs/msg/RxmRAWX_Meas"]
    meas = [Meas(**_ublox_fields(out, fields)) for fields in measurements]
    week = int(t // SECONDS_PER_WEEK)
    fields = {
        "rcvTOW": t - week * SECONDS_PER_WEEK,
        "week": week,
        "leapS": 18,
        "numMeas": len(meas),
        "recStat": 1,
        "version": 1,
        "reserved1": np.zeros(2, np.uint8),
        "meas": meas,
    }
    receive = ros_ns(t + GNSS_LATENCY_S)
    if ros2:
        fields["header"] = out.header(receive)
    message = out.types["ublox_msgs/msg/RxmRAWX"](**_ublox_fields(out, fields))
    out.write("/ublox/rxmraw", "ublox_msgs/msg/RxmRAWX", receive, message)


def ublox_sfrbx(out: SmallBag, t: float, gnss_id: int, sv_id: int, freq_id: int, words) -> None:
    """One ``/ublox/rxmsfrb`` RxmSFRBX received at ``t`` (GPS)."""
    fields = {"gnssId": gnss_id, "svId": sv_id, "freqId": freq_id, "numWords": len(words)}
    fields |= {"reserved0": 0, "chn": 1, "version": 2, "reserved1": 0}
    fields["dwrd"] = np.asarray(words, dtype=np.uint32)
    if out.ros2:
        fields["header"] = out.header(ros_ns(t))
    message = out.types["ublox_msgs/msg/RxmSFRBX"](**_ublox_fields(out, fields))
    out.write("/ublox/rxmsfrb", "ublox_msgs/msg/RxmSFRBX", ros_ns(t), message)


def _ublox(out: SmallBag, seq) -> None:
    for t, sats in _epochs(seq.observations):
        meas = []
        for system, prn, values in sats:
            if "D1C" not in values:
                continue
            meas.append(
                {
                    "prMes": values.get("C1C", 0.0),
                    "cpMes": 0.0,
                    "doMes": values["D1C"],
                    "gnssId": UBX_GNSS_ID[system],
                    "svId": prn,
                    "sigId": 0,
                    "freqId": 0,
                    "locktime": 1000,
                    "cno": round(values.get("S1C", 0.0)),
                    "prStdev": 3,
                    "cpStdev": 0,
                    "doStdev": 4,
                    "trkStat": 1 if "C1C" in values else 0,
                    "reserved3": 0,
                }
            )
        ublox_rawx(out, t, meas)
    _sfrbx(out, seq.navigation)


def lnav_dict(kepler, k: int) -> dict[str, float]:
    """The LNAV fields of a GPS record (as tests/helpers/lnav.py's encoder takes them)."""
    p = {name: float(values[k]) for name, values in kepler.params.items()}
    ura = next((i for i, v in enumerate(URA_METERS) if v >= p["accuracy"]), 15)
    p.update(ura_index=ura, iodc=int(p["iode"]), toc_sow=float(kepler.toc[k]) % SECONDS_PER_WEEK)
    return p


def _sfrbx(out: SmallBag, nav) -> None:
    """GPS LNAV subframes 1–3 of each GPS record, Galileo I/NAV words 1–5 of each Galileo one
    (word 5's GST 10 min before toe) and GLONASS strings 1–4 of each GLONASS one, sent from 30 s
    before its reference time, a subframe, page or string a second."""
    kepler = nav.kepler
    for k in np.flatnonzero(kepler.system == "G"):
        t = float(kepler.toc[k])
        for n, words in enumerate(encode_ephemeris(lnav_dict(kepler, k), int(t % 604800) // 6)):
            ublox_sfrbx(out, t + n, 0, int(kepler.prn[k]), 0, with_parity(words))
    for k in np.flatnonzero(kepler.system == "E"):
        t, svid = float(kepler.toc[k]), int(kepler.prn[k])
        eph = {name: float(values[k]) for name, values in kepler.params.items()}
        eph["toc_sow"] = t % SECONDS_PER_WEEK
        for n, word in enumerate(galileo_words(svid, eph, t - 600.0)):
            ublox_sfrbx(out, t - 30.0 + n, 2, svid, 0, galileo_page(word))
    glonass = nav.glonass
    for k in range(len(glonass)):
        params = {name: float(values[k]) for name, values in glonass.params.items()}
        t, slot = float(glonass.toc[k]), int(glonass.prn[k])
        for n, string in enumerate(encode_strings(slot, t, params)):
            freq_id = int(params["channel"]) + 7
            ublox_sfrbx(out, t - 30.0 + n, 6, slot, freq_id, sfrbx_words(string))


def _truth(out: SmallBag, seq) -> None:
    truth = seq.truth
    Odometry = out.types["nav_msgs/msg/Odometry"]
    Pose = out.types["geometry_msgs/msg/Pose"]
    PoseCov = out.types["geometry_msgs/msg/PoseWithCovariance"]
    Twist = out.types["geometry_msgs/msg/Twist"]
    TwistCov = out.types["geometry_msgs/msg/TwistWithCovariance"]
    Point = out.types["geometry_msgs/msg/Point"]
    NavSatFix = out.types["sensor_msgs/msg/NavSatFix"]
    Status = out.types["sensor_msgs/msg/NavSatStatus"]
    quats = truth.orientations.as_quat()
    antenna = truth.positions + truth.orientations.apply(np.array(seq.antenna_lever_arm_m))
    ecef = seq.enu.enu_to_ecef(antenna)
    lat, lon, height = ecef_to_geodetic(ecef)
    for k, t_gps in enumerate(truth.t):
        t = ros_ns(float(t_gps))
        x, y, z = truth.positions[k]
        pose = Pose(position=Point(x=x, y=y, z=z), orientation=_quat(out, quats[k]))
        still = Twist(linear=_vec(out, 0, 0, 0), angular=_vec(out, 0, 0, 0))
        out.write(
            "/ground_truth",
            "nav_msgs/msg/Odometry",
            t,
            Odometry(
                header=out.header(t, "enu"),
                child_frame_id="base_link",
                pose=PoseCov(pose=pose, covariance=np.zeros(36)),
                twist=TwistCov(twist=still, covariance=np.zeros(36)),
            ),
        )
        if k % 10 == 0:
            out.write(
                "/fix",
                "sensor_msgs/msg/NavSatFix",
                t,
                NavSatFix(
                    header=out.header(t, "gps"),
                    status=Status(status=0, service=1),
                    latitude=float(np.degrees(lat[k])),
                    longitude=float(np.degrees(lon[k])),
                    altitude=float(height[k]),
                    position_covariance=np.zeros(9),
                    position_covariance_type=0,
                ),
            )
