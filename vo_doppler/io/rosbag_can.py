"""A CAN topic of a ROS bag → the wheel speed and the yaw rate, decoded with a DBC as a CAN log
is.

``can_msgs/msg/Frame`` (ROS 1 and ROS 2 alike: ``id``, ``is_rtr``, ``is_extended``,
``is_error``, ``dlc``, ``data[8]``): each message is one classic CAN frame at the import's
message time (header stamp or receive time, on GPS time). The frames go through the CAN log
decoder of :mod:`vo_doppler.io.can` unchanged: cantools decodes the ``MESSAGE.SIGNAL`` names,
the DBC unit is converted to SI (km/h → m/s, deg/s → rad/s), several wheel-speed signals are
averaged, the yaw rate is made counter-clockwise positive by the sign given (−1 for a bus that
reports clockwise-positive yaw rate), the samples are put in time order, and isolated values
beyond a vehicle's range are skipped.

Error and remote (RTR) frames are dropped, as the CAN log reader drops them. A message that
cannot be a frame — a ``dlc`` beyond 8 or beyond its data, an ``id`` beyond 29 bits or, without
``is_extended``, beyond 11 bits — is an :class:`~vo_doppler.errors.InputError` naming the bag,
topic and message index. A frame of a decoded message shorter than its DBC length is skipped
(its missing bytes would decode as made-up values) and counted in a warning naming the first
such message's index; a topic without two decodable frames of each asked-for message is an
error.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.can import (
    MAX_ARBITRATION_ID,
    SignalError,
    SignalRef,
    decode_motion,
    frames_from_arrays,
    load_dbc,
    parse_signal_list,
)
from vo_doppler.io.can_report import CanDecodeReport
from vo_doppler.io.rosbag_bag import Bag
from vo_doppler.io.rosbag_types import field as get
from vo_doppler.model.series import SensorSeries

MAX_STANDARD_ID = 0x7FF
"""The largest 11-bit (standard) identifier."""
MAX_CLASSIC_DLC = 8

MessageTime = Callable[[str, int, object], float]
"""``time(topic, receive_ns, message)``: a message's GPS time (the import's stamp choice)."""


@dataclass
class CanSignals:
    """What the CAN topic gave: the wheel speed (m/s) and the yaw rate (rad/s, counter-clockwise
    positive), each None when not asked for; what decoding found, the source of each, and the
    warnings for the import."""

    speed: SensorSeries | None
    yaw_rate: SensorSeries | None
    report: CanDecodeReport
    speed_source: str
    yaw_rate_source: str
    warnings: list[str]


def _frames(bag: Bag, topic: str, time: MessageTime):
    """Times, ids, payloads (``dlc`` bytes) and message indices of the topic's data frames."""
    t, ids, payloads, indices = [], [], [], []
    for index, receive_ns, m in bag.messages(topic):
        if bool(get(m, "is_error", False)) or bool(get(m, "is_rtr", False)):
            continue
        frame_id, dlc = int(get(m, "id", 0)), int(get(m, "dlc", 0))
        data = bytes(np.asarray(get(m, "data", ()), dtype=np.uint8))
        extended = bool(get(m, "is_extended", False))
        if frame_id > (MAX_ARBITRATION_ID if extended else MAX_STANDARD_ID):
            bits = 29 if extended else "11 (is_extended is false)"
            raise bag.error(topic, index, f"CAN id 0x{frame_id:X} is beyond {bits} bits")
        if dlc > min(MAX_CLASSIC_DLC, len(data)):
            raise bag.error(
                topic,
                index,
                f"dlc {dlc} with {len(data)} data bytes (a classic CAN frame holds at most "
                f"{MAX_CLASSIC_DLC})",
            )
        t.append(time(topic, receive_ns, m))
        ids.append(frame_id)
        payloads.append(data[:dlc])
        indices.append(index)
    return np.array(t, dtype=float), np.array(ids, dtype=np.int64), payloads, indices


def read_can_signals(
    bag: Bag,
    topic: str,
    time: MessageTime,
    dbc_path: str | Path,
    wheel_speed: str | None,
    yaw_rate: str | None = None,
    yaw_rate_sign: float = 1.0,
) -> CanSignals:
    """The mean of the ``wheel_speed`` signals (``MSG.A,MSG.B``) and the ``yaw_rate`` signal
    (``MSG.SIG``, times ``yaw_rate_sign``: −1 for a bus that reports clockwise-positive yaw
    rate) of the topic, decoded with the DBC (module docstring); a signal the DBC lacks or whose
    unit is not a speed (an angular rate) is an error naming the DBC."""
    db = load_dbc(dbc_path)
    try:
        wheels = parse_signal_list(wheel_speed) if wheel_speed is not None else []
        if wheel_speed is not None and not wheels:
            raise SignalError(f"no wheel-speed signal in {wheel_speed!r}")
        yaw = SignalRef.parse(yaw_rate) if yaw_rate is not None else None
    except SignalError as exc:
        raise SignalError(str(exc), dbc_path) from exc
    t, ids, payloads, indices = _frames(bag, topic, time)
    frames = frames_from_arrays(t, ids, payloads, source=f"{bag.path}: topic {topic}")
    try:
        motion = decode_motion(
            frames, db, yaw_rate=yaw, wheel_speed=wheels, yaw_rate_sign=yaw_rate_sign
        )
    except SignalError as exc:
        raise SignalError(str(exc), dbc_path) from exc
    except InputError as exc:  # time order, values beyond a vehicle's range
        raise InputError(f"topic {topic}: {exc}", bag.path) from exc
    refs = [*wheels, *([yaw] if yaw else [])]
    messages = (db.get_message_by_name(ref.message) for ref in refs)
    lengths = {m.frame_id: (m.name, m.length) for m in messages}
    report = motion.report
    warnings = [f"{bag.path}: topic {topic}: {text}" for text in report.problems()]
    short = [
        (k, frame_id, len(data))
        for k, (frame_id, data) in enumerate(zip(ids, payloads, strict=True))
        if frame_id in lengths and len(data) < lengths[frame_id][1]
    ]
    if short:
        k, frame_id, size = short[0]
        name, length = lengths[int(frame_id)]
        warnings.append(
            f"{bag.path}: topic {topic}: {len(short)} frames of {name} shorter than its DBC "
            f"length of {length} bytes skipped (the first, message {indices[k]}: dlc {size})"
        )
    for series, asked in ((motion.speed, wheels), (motion.yaw_rate, [yaw] if yaw else [])):
        if asked and (series is None or len(series) < 2):
            names = ", ".join(sorted({ref.message for ref in asked}))
            raise InputError(
                f"topic {topic}: fewer than 2 decodable frames of {names} ({report.summary()})",
                bag.path,
            )
    sign = " × −1 (clockwise positive on the bus)" if yaw_rate_sign < 0 else ""
    return CanSignals(
        motion.speed,
        motion.yaw_rate,
        report,
        f"CAN topic {topic}: {wheel_speed} decoded with {dbc_path}",
        f"CAN topic {topic}: {yaw_rate}{sign} decoded with {dbc_path}",
        warnings,
    )
