"""The error of a log that cannot be used (one line naming the file and what is wrong)."""

from drill_sim_ros.model.errors import DrillSimError


class LogError(DrillSimError):
    """The log cannot be used; the message names the file and what is wrong."""
