"""Open a rerun RecordingStream on the requested sinks, with the dashboard blueprint.

``serve`` hosts a gRPC server bound to 127.0.0.1 only (rerun's ``GrpcServerSink`` takes a
``bind_ip``; ``rr.serve_grpc`` would bind 0.0.0.0), holding at most ``serve_memory_mib`` of
data for viewers (beyond it the server drops the oldest).
"""

from __future__ import annotations

import socket
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import rerun as rr
import rerun.blueprint as rrb

from drill_sim_ros.viz.entities import APP_ID

LOOPBACK = "127.0.0.1"
DEFAULT_SERVE_PORT = 9876
DEFAULT_VIEWER_URL = f"rerun+http://{LOOPBACK}:{DEFAULT_SERVE_PORT}/proxy"
# What --serve keeps for viewers that connect later (rerun's default is 1 GiB); the bridge
# with --serve and no viewer grew 6.6 MiB a minute at the sim's default 100 Hz telemetry.
DEFAULT_SERVE_MEMORY_MIB = 256
SERVE_MEMORY_MIB_RANGE = (16, 65536)


def sinks_for(save: str | Path | None = None, connect: str | None = None,
              serve_port: int | None = None,
              serve_memory_mib: int = DEFAULT_SERVE_MEMORY_MIB,
              ) -> list[rr.FileSink | rr.GrpcSink | rr.GrpcServerSink]:
    """FileSink for ``save``, GrpcSink for ``connect``, loopback server for ``serve_port``."""
    sinks: list[rr.FileSink | rr.GrpcSink | rr.GrpcServerSink] = []
    if save is not None:
        Path(save).parent.mkdir(parents=True, exist_ok=True)
        sinks.append(rr.FileSink(str(save)))
    if connect is not None:
        sinks.append(rr.GrpcSink(connect))
    if serve_port is not None:
        sinks.append(rr.GrpcServerSink(bind_ip=LOOPBACK, port=serve_port,
                                       server_memory_limit=f"{serve_memory_mib}MiB"))
    return sinks


def open_recording(blueprint: rrb.Blueprint, *, save: str | Path | None = None,
                   connect: str | None = None, serve_port: int | None = None,
                   serve_memory_mib: int = DEFAULT_SERVE_MEMORY_MIB,
                   recording_id: str | None = None) -> rr.RecordingStream:
    """A new recording of application ``drill_sim_ros`` streaming to the given sinks.

    Streams opened with the same ``recording_id`` are parts of one recording.
    """
    sinks = sinks_for(save, connect, serve_port, serve_memory_mib)
    if not sinks:
        raise ValueError("no rerun sink: give save, connect or serve_port")
    rec = rr.RecordingStream(APP_ID, recording_id=recording_id)
    # sim_time is the only timeline: what is logged row by row (``log``) gets no wall-clock
    # log_time or log_tick, so two recordings of one run give the same dashboard
    rec.set_log_time_enabled(False)
    rec.set_log_tick_enabled(False)
    rec.set_sinks(*sinks, default_blueprint=blueprint)
    return rec


class Recordings:
    """The recording streams the dashboard logs to at the moment.

    It has the methods the ``log_*`` functions call (``send_columns``, ``log`` and
    ``set_time``) and hands each call to every attached stream, so one stream (a viewer's)
    can be attached and detached without touching the others (a FileSink cannot be
    re-attached: it would truncate its file).
    """

    def __init__(self, *streams: rr.RecordingStream) -> None:
        self.streams = list(streams)

    def attach(self, stream: rr.RecordingStream) -> None:
        self.streams.append(stream)

    def detach(self, stream: rr.RecordingStream) -> None:
        self.streams.remove(stream)

    def send_columns(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.send_columns(*args, **kwargs)

    def log(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.log(*args, **kwargs)

    def set_time(self, *args: Any, **kwargs: Any) -> None:
        for stream in self.streams:
            stream.set_time(*args, **kwargs)


def flush_recording(rec: rr.RecordingStream, timeout_s: float) -> str | None:
    """Wait up to ``timeout_s`` until every sink has taken what was logged; None, or one line
    on why not (a viewer gone away, or not reading)."""
    try:
        rec.flush(timeout_sec=timeout_s)
    except RuntimeError as exc:             # rerun reports a sink it cannot flush this way
        return str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return None


def close_recording(rec: rr.RecordingStream, timeout_s: float = 10.0) -> str | None:
    """Flush everything (the .rrd gets its footer) and detach the sinks.

    Returns None, or one line on why a sink could not be flushed (a viewer gone away).
    """
    problem = flush_recording(rec, timeout_s)
    rec.disconnect()
    return problem


def tcp_address(url: str) -> tuple[str, int]:
    """(host, port) of a ``rerun+http://host:port/proxy`` URL (port 9876 by default)."""
    parsed = urlsplit(url)
    return parsed.hostname or LOOPBACK, parsed.port or DEFAULT_SERVE_PORT


def viewer_listening(url: str, timeout_s: float = 0.5) -> bool:
    """True if something accepts TCP connections at ``url``'s host and port."""
    try:
        with socket.create_connection(tcp_address(url), timeout=timeout_s):
            return True
    except OSError:
        return False


def port_free(port: int) -> str | None:
    """None if ``port`` can be bound on 127.0.0.1, else the reason."""
    with socket.socket() as sock:
        try:
            sock.bind((LOOPBACK, port))
        except OSError as exc:
            return exc.strerror or str(exc)
    return None
