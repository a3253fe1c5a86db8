"""Real-time pacing of a simulation on the monotonic clock: deadlines and the tick thread.

ROS-free: sim_node drives its session with these; nothing here knows ROS exists.
"""
