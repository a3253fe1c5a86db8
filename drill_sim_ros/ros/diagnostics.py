"""sim_node's /diagnostics: the two statuses built from a copy of the node's figures.

``simulation``: state, sim time, target and achieved real-time factor, overruns, tick
lateness, rejected, stale and lost commands, matched command publishers, lockstep's wait,
recorder counts (ERROR on a numerical fault, WARN while lockstep waits past
``lockstep.warn_after_s``, on overruns or recorder drops). ``bit dynamics``: mode, stick-slip
severity, under-torque ratio and stick fraction of the last window (WARN in stick-slip).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from drill_sim_ros import topics
from drill_sim_ros.model.analysis import Severity
from drill_sim_ros.realtime.pacing import lateness_percentiles_ms
from drill_sim_ros.ros.messages import stamp, status

SSI_STICK_SLIP = 0.5          # above this severity the dynamics status warns


@dataclass(frozen=True)
class Figures:
    """What /diagnostics reports, copied under the node's lock."""

    state: str
    fault: str | None
    sim_time_s: float
    rtf: float
    achieved: float
    overruns: int
    lateness_ns: np.ndarray
    rejected: int
    saturated: int
    dropped: int
    record_error: str | None
    written: int
    severity: Severity
    stick_fraction: float
    mode: str
    window_s: float
    # command-triggered lockstep's handshake (drill_sim_ros.ros.handshake)
    stale: int = 0                 # commands that did not answer the latest sample
    lost_commands: int = 0         # commands DDS reports lost on their way
    command_publishers: int = 0    # publishers matched on drill/cmd/top_drive
    waiting: str | None = None     # what lockstep waits for, past lockstep.warn_after_s
    waits: int = 0                 # waits that went past lockstep.warn_after_s


def diagnostics(figures: Figures, time_ns: int) -> DiagnosticArray:
    """The /diagnostics message of ``figures``, stamped ``time_ns`` of simulated time."""
    msg = DiagnosticArray(status=[node_status(figures), dynamics_status(figures)])
    msg.header.stamp = stamp(time_ns)
    return msg


def node_status(f: Figures) -> DiagnosticStatus:
    p50, p99 = lateness_percentiles_ms(f.lateness_ns, 50, 99)
    values = {
        "state": f.state,
        "sim_time_s": f"{f.sim_time_s:.3f}",
        "real_time_factor_target": f"{f.rtf:g}",
        "real_time_factor_achieved": f"{f.achieved:.4g}",
        "overruns": str(f.overruns),
        "tick_lateness_p50_ms": f"{p50:.4g}",
        "tick_lateness_p99_ms": f"{p99:.4g}",
        "rejected_commands": str(f.rejected),
        "saturated_commands": str(f.saturated),
        "stale_commands": str(f.stale),
        "lost_commands": str(f.lost_commands),
        "command_publishers": str(f.command_publishers),
        "lockstep_waits": str(f.waits),
        "waiting": f.waiting or "",
        "recorder_dropped": str(f.dropped),
        "recorder_written": str(f.written),
        "fault": f.fault or "",
        "recorder_error": f.record_error or "",
    }
    if f.fault is not None:
        level, message = DiagnosticStatus.ERROR, f"numerical fault: {f.fault}"
    elif f.record_error is not None:
        level, message = DiagnosticStatus.ERROR, f"recording stopped: {f.record_error}"
    elif f.waiting is not None:
        level, message = DiagnosticStatus.WARN, f.waiting
    elif f.overruns or f.dropped:
        level, message = DiagnosticStatus.WARN, "overruns or recorder drops"
    else:
        level, message = DiagnosticStatus.OK, f.state
    return status(f"{topics.NODE_NAME}: simulation", level, message, values)


def dynamics_status(f: Figures) -> DiagnosticStatus:
    sev = f.severity
    values = {"mode": f.mode, "stick_slip_severity": f"{sev.ssi:.4g}",
              "under_torque_ratio": f"{sev.utr:.4g}",
              "stick_fraction": f"{f.stick_fraction:.4g}", "window_s": f"{f.window_s:g}"}
    stick_slip = f.stick_fraction > 0 or sev.ssi > SSI_STICK_SLIP
    level = DiagnosticStatus.WARN if stick_slip else DiagnosticStatus.OK
    message = "stick-slip" if stick_slip else "smooth drilling"
    return status(f"{topics.NODE_NAME}: bit dynamics", level, message, values)
