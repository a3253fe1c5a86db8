"""Publishers of the wrong message type on a command topic, found in the ROS graph.

DDS never matches a publisher and a subscription of different types, so a controller that
sends, say, std_msgs/Int32 on /drill/cmd/wob is silent on both sides (Fast DDS raises no
incompatible-type event here). The sim checks the graph once a second and names each such
publisher once.
"""

from __future__ import annotations

from typing import Any

# What the graph gives as the node name of an endpoint discovered before its node.
UNKNOWN = "_NODE_NAME_UNKNOWN_"


class ForeignCommandTypes:
    """Remembers which (topic, type) pairs were already reported."""

    def __init__(self, expected: dict[str, str]) -> None:
        self._expected = expected
        self._reported: set[tuple[str, str]] = set()

    def new_reasons(self, node: Any) -> list[str]:
        """One line per publisher type not seen before that the sim will never receive."""
        reasons = []
        for topic, wanted in self._expected.items():
            for info in node.get_publishers_info_by_topic(topic):
                key = (topic, info.topic_type)
                if info.topic_type == wanted or key in self._reported:
                    continue
                if not info.node_name or info.node_name.startswith(UNKNOWN):
                    continue                # discovered before its node: name it next time
                self._reported.add(key)
                reasons.append(f"{info.node_namespace.rstrip('/')}/{info.node_name} publishes "
                               f"{info.topic_type} on {topic}; the sim takes only {wanted}, so "
                               "those commands are never received")
        return reasons
