"""QoS profiles <-> the ``offered_qos_profiles`` YAML that rosbag2 (Jazzy, metadata v9) stores.

rosbag2 keeps one YAML sequence per topic, one entry per publisher, with policy names as
strings (``keep_last``, ``reliable``, ``volatile``, ``automatic``) and durations as
``{sec, nsec}``. The same text goes into the MCAP channel metadata and into the ``rosbag2``
metadata record.
"""

from __future__ import annotations

from collections.abc import Iterable

import yaml
from rclpy.duration import Duration
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)

from drill_sim_ros.model.telemetry import NS_PER_S

# Keep up to this many samples per topic in a recorder's or replayer's DDS queue.
DEFAULT_DEPTH = 1000


def _duration(value: Duration) -> dict[str, int]:
    sec, nsec = divmod(int(value.nanoseconds), NS_PER_S)
    return {"sec": sec, "nsec": nsec}


def qos_to_dict(profile: QoSProfile) -> dict:
    """One rosbag2 v9 QoS entry."""
    return {
        "history": profile.history.name.lower(),
        "depth": int(profile.depth),
        "reliability": profile.reliability.name.lower(),
        "durability": profile.durability.name.lower(),
        "deadline": _duration(profile.deadline),
        "lifespan": _duration(profile.lifespan),
        "liveliness": profile.liveliness.name.lower(),
        "liveliness_lease_duration": _duration(profile.liveliness_lease_duration),
        "avoid_ros_namespace_conventions": bool(profile.avoid_ros_namespace_conventions),
    }


def qos_profiles_yaml(profiles: Iterable[QoSProfile]) -> str:
    """The ``offered_qos_profiles`` text for a list of publishers' profiles ('' when none)."""
    entries = [qos_to_dict(p) for p in profiles]
    return yaml.safe_dump(entries, default_flow_style=False, sort_keys=False) if entries else ""


def _policy(enum: type, value: object, fallback: object) -> object:
    if isinstance(value, int):
        return enum(value)
    return enum.__members__.get(str(value).upper(), fallback)


def replay_qos(offered_yaml: str, depth: int = DEFAULT_DEPTH) -> QoSProfile:
    """A publisher profile matching what the original publishers offered.

    Reliability and durability are what subscribers match against; with several differing
    publishers, fall back to the permissive offer (reliable + volatile), as rosbag2 does.
    """
    entries = yaml.safe_load(offered_yaml) if offered_yaml else None
    profile = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth)
    if not entries:
        return profile
    reliabilities = {_policy(ReliabilityPolicy, e.get("reliability"), None) for e in entries}
    durabilities = {_policy(DurabilityPolicy, e.get("durability"), None) for e in entries}
    if len(reliabilities) == 1 and ReliabilityPolicy.BEST_EFFORT in reliabilities:
        profile.reliability = ReliabilityPolicy.BEST_EFFORT
    if len(durabilities) == 1 and DurabilityPolicy.TRANSIENT_LOCAL in durabilities:
        profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile


def subscription_qos(offered: list[QoSProfile], depth: int = DEFAULT_DEPTH) -> QoSProfile:
    """A recorder subscription compatible with every offer (rosbag2's adapt_request_to_offers).

    Reliable only if every publisher is reliable; transient-local only if every one is.
    """
    profile = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=depth)
    profile.liveliness = LivelinessPolicy.SYSTEM_DEFAULT
    if offered and any(p.reliability != ReliabilityPolicy.RELIABLE for p in offered):
        profile.reliability = ReliabilityPolicy.BEST_EFFORT
    if offered and all(p.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in offered):
        profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile
