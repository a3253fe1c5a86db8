"""drill_sim_ros: real-time simulation of drill-bit stick-slip (Richard, Germay & Detournay 2007)."""

__version__ = "0.1.0"
