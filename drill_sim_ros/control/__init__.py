"""Reference top-drive controllers and the closed-loop bench (ROS-free)."""
