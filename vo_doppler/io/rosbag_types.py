"""Message types of ROS bags that rosbags' stock type stores do not hold, and field access by
name across the ROS 1 and ROS 2 spellings of one interface.

Written here from the interfaces' field lists (they are interface facts):

- ``gnss_comm`` (HKUST Aerial Robotics, used by GVINS): ``GnssTimeMsg`` (GPS week, time of
  week), ``GnssObsMsg`` (one satellite's measurements of one epoch, one array entry per
  frequency), ``GnssMeasMsg`` (one epoch: a list of ``GnssObsMsg``), ``GnssEphemMsg``
  (GPS/Galileo/BeiDou Keplerian ephemeris), ``GnssGloEphemMsg`` (GLONASS) and
  ``StampedFloat64Array`` (the receiver's ionosphere parameters, Klobuchar α0–α3 β0–β3);
- ``tf2_msgs/TFMessage`` (missing from rosbags' ROS 1 store);
- ``can_msgs/Frame`` (ros_canopen / ros2_canopen, socketcan_bridge: one classic CAN frame, the
  same fields in ROS 1 and ROS 2: id, RTR / extended / error flags, dlc, 8 data bytes);
- ``ublox_msgs`` (the u-blox ROS driver): ``RxmRAWX`` with its measurement block and
  ``RxmSFRBX``, once with the ROS 1 driver's camelCase names (``RxmRAWX_Meas``, ``rcvTOW``,
  ``prMes``) and once with the ROS 2 driver's snake_case names (``RxmRAWXMeas``, ``rcv_tow``,
  ``pr_mes``).

A ROS 1 bag (and a ROS 2 bag written by Iron or later, or as MCAP) carries the definitions of
its own types; those are used first, these fill in what a bag does not define. Because the
drivers' releases spell the same field differently, the readers look fields up with
:func:`field`, which ignores case and underscores (``rcvTOW`` = ``rcv_tow`` = ``rcvTow``).
"""

from __future__ import annotations

from functools import cache

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

GNSS_COMM = {
    "gnss_comm/msg/GnssTimeMsg": "uint32 week\nfloat64 tow\n",
    "gnss_comm/msg/GnssObsMsg": """
gnss_comm/GnssTimeMsg time
uint32 sat
float64[] freqs
float64[] CN0
uint8[] LLI
uint8[] code
float64[] psr
float64[] psr_std
float64[] cp
float64[] cp_std
float64[] dopp
float64[] dopp_std
uint8[] status
""",
    "gnss_comm/msg/GnssMeasMsg": "gnss_comm/GnssObsMsg[] meas\n",
    "gnss_comm/msg/GnssEphemMsg": """
uint32 sat
gnss_comm/GnssTimeMsg ttr
gnss_comm/GnssTimeMsg toe
gnss_comm/GnssTimeMsg toc
float64 toe_tow
uint32 week
uint32 iode
uint32 iodc
uint32 health
uint32 code
float64 ura
float64 A
float64 e
float64 i0
float64 omg
float64 OMG0
float64 M0
float64 delta_n
float64 OMG_dot
float64 i_dot
float64 cuc
float64 cus
float64 crc
float64 crs
float64 cic
float64 cis
float64 af0
float64 af1
float64 af2
float64 tgd0
float64 tgd1
float64 A_dot
float64 n_dot
""",
    "gnss_comm/msg/GnssGloEphemMsg": """
uint32 sat
gnss_comm/GnssTimeMsg ttr
gnss_comm/GnssTimeMsg toe
int32 freqo
uint32 iode
uint32 health
uint32 age
float64 ura
float64 pos_x
float64 pos_y
float64 pos_z
float64 vel_x
float64 vel_y
float64 vel_z
float64 acc_x
float64 acc_y
float64 acc_z
float64 tau_n
float64 gamma
float64 delta_tau_n
""",
    "gnss_comm/msg/StampedFloat64Array": "std_msgs/Header header\nfloat64[] data\n",
}

CAN_MSGS = {
    "can_msgs/msg/Frame": """
std_msgs/Header header
uint32 id
bool is_rtr
bool is_extended
bool is_error
uint8 dlc
uint8[8] data
""",
}

UBLOX_ROS1 = {
    "ublox_msgs/msg/RxmRAWX_Meas": """
float64 prMes
float64 cpMes
float32 doMes
uint8 gnssId
uint8 svId
uint8 sigId
uint8 freqId
uint16 locktime
int8 cno
uint8 prStdev
uint8 cpStdev
uint8 doStdev
uint8 trkStat
uint8 reserved3
""",
    "ublox_msgs/msg/RxmRAWX": """
float64 rcvTOW
uint16 week
int8 leapS
uint8 numMeas
uint8 recStat
uint8 version
uint8[2] reserved1
ublox_msgs/RxmRAWX_Meas[] meas
""",
    "ublox_msgs/msg/RxmSFRBX": """
uint8 gnssId
uint8 svId
uint8 reserved0
uint8 freqId
uint8 numWords
uint8 chn
uint8 version
uint8 reserved1
uint32[] dwrd
""",
}

UBLOX_ROS2 = {
    "ublox_msgs/msg/RxmRAWXMeas": """
float64 pr_mes
float64 cp_mes
float32 do_mes
uint8 gnss_id
uint8 sv_id
uint8 sig_id
uint8 freq_id
uint16 locktime
int8 cno
uint8 pr_stdev
uint8 cp_stdev
uint8 do_stdev
uint8 trk_stat
uint8 reserved1
""",
    "ublox_msgs/msg/RxmRAWX": """
std_msgs/Header header
float64 rcv_tow
uint16 week
int8 leap_s
uint8 num_meas
uint8 rec_stat
uint8 version
uint8[2] reserved1
ublox_msgs/RxmRAWXMeas[] meas
""",
    "ublox_msgs/msg/RxmSFRBX": """
std_msgs/Header header
uint8 gnss_id
uint8 sv_id
uint8 reserved0
uint8 freq_id
uint8 num_words
uint8 chn
uint8 version
uint8 reserved1
uint32[] dwrd
""",
}


TF2 = {"tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n"}
"""tf2's transform list, which rosbags' ROS 1 Noetic store lacks."""


def project_types(ros2: bool) -> dict:
    """The project's definitions as a rosbags types dict (ROS 1 or ROS 2 spelling of ublox)."""
    types: dict = {}
    ublox = UBLOX_ROS2 if ros2 else UBLOX_ROS1
    for name, text in (*GNSS_COMM.items(), *CAN_MSGS.items(), *ublox.items()):
        types.update(get_types_from_msg(text, name))
    return types


@cache
def typestore(ros2: bool) -> Typestore:
    """rosbags' stock store (ROS 2 Humble or ROS 1 Noetic) with the project's types added
    (built once per process: do not register more types in it)."""
    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    types = project_types(ros2)
    for name, text in TF2.items():
        if name not in store.types:
            types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


def _key(name: str) -> str:
    return name.replace("_", "").lower()


@cache
def _names(cls: type) -> dict[str, str]:
    """Spelling-free key → attribute name of a message class's fields."""
    return {_key(a): a for a in getattr(cls, "__dataclass_fields__", {})}


def field(message: object, name: str, default: object = None) -> object:
    """The field of ``message`` named ``name`` in any spelling (case and underscores ignored);
    ``default`` when it has none."""
    attribute = _names(type(message)).get(_key(name))
    return default if attribute is None else getattr(message, attribute)


def has_field(message: object, name: str) -> bool:
    """Whether ``message`` has a field named ``name`` in any spelling."""
    return _key(name) in _names(type(message))
