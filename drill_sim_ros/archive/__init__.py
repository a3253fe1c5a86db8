"""MCAP archive of drill_sim runs: ROS 2 profile writer, reader, recorder, replay and reindex.

Files follow the MCAP ``ros2`` profile that rosbag2's MCAP storage (Jazzy), Foxglove, rosbags
and mcap-ros2-support read: ``ros2msg`` schemas, ``cdr`` messages, a summary with statistics,
per-channel ``offered_qos_profiles`` and ``topic_type_hash``.
"""
