"""Message classes of the ROS interface and small message builders."""

from __future__ import annotations

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from drill_sim_ros import topics
from drill_sim_ros.archive.ros_types import message_class
from drill_sim_ros.model.telemetry import NS_PER_S

HARDWARE_ID = "drill_sim_ros"
# /drill/run_info is published once and latched: a late subscriber (a recorder, a bridge)
# still gets it.
RUN_INFO_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                          reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL)
# What a controller reads, drill/surface/measured, is latched the same way: a subscriber
# asking for transient local gets the latest sample when it connects, whether it started
# before sim_node, after it, or again mid-run; volatile subscribers still match.
LATEST_SAMPLE_QOS = RUN_INFO_QOS
# drill/telemetry (the whole truth, for tests and tools) keeps a deeper history, so that a
# subscriber falling behind in free run still gets lost samples repaired; a transient-local
# subscriber joining gets up to that many recent samples (one, t = 0, at the start of a run).
TELEMETRY_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                           reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)


def type_of(topic: str) -> type:
    """The message class of one of the topics in :mod:`drill_sim_ros.topics` (a typed one
    needs drill_sim_msgs)."""
    return message_class({**topics.MSG_TYPES, **topics.TYPED_MSG_TYPES}[topic])


def stamp(time_ns: int) -> Time:
    """builtin_interfaces/Time of an integer nanosecond count."""
    sec, nanosec = divmod(int(time_ns), NS_PER_S)
    return Time(sec=sec, nanosec=nanosec)


def stamp_ns(time: Time) -> int:
    """The integer nanoseconds of a builtin_interfaces/Time."""
    return time.sec * NS_PER_S + time.nanosec


def status(name: str, level: bytes, message: str, values: dict[str, str],
           hardware_id: str = HARDWARE_ID) -> DiagnosticStatus:
    """A DiagnosticStatus with ``values`` as key/value pairs."""
    return DiagnosticStatus(level=level, name=name, message=message, hardware_id=hardware_id,
                            values=[KeyValue(key=k, value=v) for k, v in values.items()])
