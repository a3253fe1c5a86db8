"""Pure numerical core (numpy/numba). Never imports rclpy, mcap or rerun."""
