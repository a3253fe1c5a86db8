"""Studies: regime maps computed on Dask distributed, and the paper's figures (no ROS)."""
