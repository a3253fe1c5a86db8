"""Calibrating the twin from a rig's surface log: ``drill_sim fit`` (docs/fit.md)."""
