"""Open a rerun RecordingStream on the requested sinks, with the dashboard blueprint.

``serve`` hosts a gRPC server bound to 127.0.0.1 only (rerun's ``GrpcServerSink`` takes a
``bind_ip``; ``rr.serve_grpc`` would bind 0.0.0.0).
"""

from __future__ import annotations

from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb

from drill_sim_ros.viz.entities import APP_ID

LOOPBACK = "127.0.0.1"
DEFAULT_SERVE_PORT = 9876
DEFAULT_VIEWER_URL = f"rerun+http://{LOOPBACK}:{DEFAULT_SERVE_PORT}/proxy"


def sinks_for(save: str | Path | None = None, connect: str | None = None,
              serve_port: int | None = None) -> list[rr.FileSink | rr.GrpcSink |
                                                       rr.GrpcServerSink]:
    """FileSink for ``save``, GrpcSink for ``connect``, loopback server for ``serve_port``."""
    sinks: list[rr.FileSink | rr.GrpcSink | rr.GrpcServerSink] = []
    if save is not None:
        Path(save).parent.mkdir(parents=True, exist_ok=True)
        sinks.append(rr.FileSink(str(save)))
    if connect is not None:
        sinks.append(rr.GrpcSink(connect))
    if serve_port is not None:
        sinks.append(rr.GrpcServerSink(bind_ip=LOOPBACK, port=serve_port))
    return sinks


def open_recording(blueprint: rrb.Blueprint, *, save: str | Path | None = None,
                   connect: str | None = None,
                   serve_port: int | None = None) -> rr.RecordingStream:
    """A new recording of application ``drill_sim_ros`` streaming to the given sinks."""
    sinks = sinks_for(save, connect, serve_port)
    if not sinks:
        raise ValueError("no rerun sink: give save, connect or serve_port")
    rec = rr.RecordingStream(APP_ID)
    rec.set_sinks(*sinks, default_blueprint=blueprint)
    return rec


def close_recording(rec: rr.RecordingStream, timeout_s: float = 10.0) -> None:
    """Flush everything (the .rrd gets its footer) and detach the sinks."""
    rec.flush(timeout_sec=timeout_s)
    rec.disconnect()
