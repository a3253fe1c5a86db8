"""drill_sim_ros: real-time drill-bit stick-slip simulation (Richard, Germay & Detournay 2007)."""

__version__ = "0.1.0"
