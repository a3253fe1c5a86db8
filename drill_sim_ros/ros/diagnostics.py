"""sim_node's /diagnostics: the two statuses built from a copy of the node's figures.

Each status is named ``<node>: simulation`` and ``<node>: bit dynamics`` after the node's
fully qualified name (``rig1/drill_sim`` under ``-r __ns:=/rig1``), with the rig (the
namespace) as hardware_id, so two sims stay apart in an aggregator. A level means a fault:

``simulation``: state, sim time, target and achieved real-time factor, overruns, tick
lateness, rejected, stale and lost commands, matched command publishers, lockstep's wait,
recorder counts. ERROR on a numerical fault or a recording that stopped; WARN while
lockstep waits past ``lockstep.warn_after_s``, while overruns or recorder drops grow (since
the last report) or when the controller fell silent (no command for ``command_timeout_s``
of sim time after one came). ``bit dynamics``: mode, stick-slip severity, under-torque
ratio and stick fraction of the last window; stick-slip is the message (and ``severity``:
none, mild, severe), the level stays OK: it is how the bit drills, not a fault of the
simulation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from drill_sim_ros import topics
from drill_sim_ros.model.analysis import Severity
from drill_sim_ros.realtime.pacing import lateness_percentiles_ms
from drill_sim_ros.ros.messages import HARDWARE_ID, stamp, status

SSI_STICK_SLIP = 0.5          # above this severity the bit is in stick-slip
SSI_SEVERE = 1.0              # at or above: full stick-slip (the bit stops in each cycle)


@dataclass(frozen=True)
class Source:
    """Who reports: the status name prefix and the hardware (rig) id."""

    name: str = topics.NODE_NAME
    hardware_id: str = HARDWARE_ID


def source_of(fully_qualified_name: str, namespace: str) -> Source:
    """The :class:`Source` of a node (``/rig1/drill_sim``, ``/rig1``): ``rig1/drill_sim``,
    hardware ``rig1``; in the root namespace ``drill_sim``, hardware ``drill_sim_ros``."""
    rig = namespace.strip("/")
    return Source(fully_qualified_name.lstrip("/"), rig or HARDWARE_ID)


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
    command_silence_s: float | None = None    # sim s since the last command (None: none)
    command_timeout_s: float = 0.0            # silence above this warns; 0 = never
    # command-triggered lockstep's handshake (drill_sim_ros.ros.handshake)
    stale: int = 0                 # commands that did not answer the latest sample
    lost_commands: int = 0         # commands DDS reports lost on their way
    command_publishers: int = 0    # publishers matched on drill/cmd/top_drive (and typed)
    telemetry_subscribers: int = 0  # subscriptions matched on drill/telemetry (recorders,
                                    # bridges, tools)
    waiting: str | None = None     # what lockstep waits for, past lockstep.warn_after_s
    waits: int = 0                 # waits that went past lockstep.warn_after_s


class Diagnostics:
    """Builds sim_node's /diagnostics messages; remembers the counts of the last report so
    that a level shows what goes wrong now, not what went wrong once."""

    def __init__(self, source: Source | None = None) -> None:
        self.source = source or Source()
        self._last_counts = (0, 0)

    def message(self, figures: Figures, time_ns: int) -> DiagnosticArray:
        counts = (figures.overruns, figures.dropped)
        growing = any(now > before for now, before in zip(counts, self._last_counts,
                                                          strict=True))
        self._last_counts = counts
        return diagnostics(figures, time_ns, self.source, growing)


def diagnostics(figures: Figures, time_ns: int, source: Source | None = None,
                growing: bool = False) -> DiagnosticArray:
    """The /diagnostics message of ``figures``, stamped ``time_ns`` of simulated time;
    ``growing``: overruns or recorder drops grew since the last report."""
    source = source or Source()
    msg = DiagnosticArray(status=[node_status(figures, source, growing),
                                  dynamics_status(figures, source)])
    msg.header.stamp = stamp(time_ns)
    return msg


def controller_silent(f: Figures) -> bool:
    """A command came, then none for more than ``command_timeout_s`` of sim time."""
    return (f.command_timeout_s > 0 and f.command_silence_s is not None
            and f.command_silence_s > f.command_timeout_s)


def node_status(f: Figures, source: Source, growing: bool = False) -> DiagnosticStatus:
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
        "telemetry_subscribers": str(f.telemetry_subscribers),
        "lockstep_waits": str(f.waits),
        "waiting": f.waiting or "",
        "recorder_dropped": str(f.dropped),
        "recorder_written": str(f.written),
        "fault": f.fault or "",
        "recorder_error": f.record_error or "",
        "command_silence_s": "" if f.command_silence_s is None else
                             f"{f.command_silence_s:.3f}",
    }
    if f.fault is not None:
        level, message = DiagnosticStatus.ERROR, f"numerical fault: {f.fault}"
    elif f.record_error is not None:
        level, message = DiagnosticStatus.ERROR, f"recording stopped: {f.record_error}"
    elif f.waiting is not None:
        level, message = DiagnosticStatus.WARN, f.waiting
    elif growing:
        level, message = DiagnosticStatus.WARN, "overruns or recorder drops"
    elif controller_silent(f):
        level, message = DiagnosticStatus.WARN, (
            f"controller silent: no command for {f.command_silence_s:.1f} s of sim time")
    else:
        level, message = DiagnosticStatus.OK, f.state
    return status(f"{source.name}: simulation", level, message, values, source.hardware_id)


def stick_slip_severity(f: Figures) -> str:
    """none, mild (the bit slows and sticks in part of the window) or severe (SSI >= 1:
    the bit stops in every cycle)."""
    if f.severity.ssi >= SSI_SEVERE:
        return "severe"
    return "mild" if f.stick_fraction > 0 or f.severity.ssi > SSI_STICK_SLIP else "none"


def dynamics_status(f: Figures, source: Source) -> DiagnosticStatus:
    sev = f.severity
    severity = stick_slip_severity(f)
    values = {"mode": f.mode, "stick_slip": severity, "stick_slip_severity": f"{sev.ssi:.4g}",
              "under_torque_ratio": f"{sev.utr:.4g}",
              "stick_fraction": f"{f.stick_fraction:.4g}", "window_s": f"{f.window_s:g}"}
    message = "smooth drilling" if severity == "none" else f"stick-slip ({severity})"
    return status(f"{source.name}: bit dynamics", DiagnosticStatus.OK, message, values,
                  source.hardware_id)
