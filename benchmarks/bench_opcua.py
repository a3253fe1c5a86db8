"""Command-triggered lockstep over OPC UA: periods per second through opcua_gateway (no asserts).

sim_node (field preset, ``lockstep:=true -p lockstep_trigger:=command``) and opcua_gateway run
as processes on loopback; this process is a plain asyncua client that, every period, reads the
quill torque, writes a speed setpoint and advances one period, three ways: the counters with
SampleCounter polled (as a PLC's cyclic task does), the counters with a data-change
subscription on SampleCounter, and the method Step. Prints periods/s of each (wall time over
the periods). Target (issue 33): >= 200 periods/s.
Usage: .venv/bin/python benchmarks/bench_opcua.py [--periods 2000]
"""

from __future__ import annotations

import argparse
import asyncio
import os
import random
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 101)))
os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)

from asyncua import Client, ua
from bench_node import stop  # the sibling script (benchmarks/ is on sys.path when run)

BIN = Path(sys.prefix) / "bin"
START_TIMEOUT_S = 90.0
DOUBLE, UINT32, INT32 = ua.VariantType.Double, ua.VariantType.UInt32, ua.VariantType.Int32
SPEED_MODE = 0                    # DriveMode (DriveModeEnum): the law gives speed setpoints


def speed_rad_s(quill_torque_nm: float) -> float:
    """A torque-feedback speed setpoint (the example controller's law)."""
    return max(0.0, 6.0 - 1e-3 * (quill_torque_nm - 3400.0))


class SampleEvents:
    """asyncua's subscription handler: the latest SampleCounter, and an event per change."""

    def __init__(self) -> None:
        self.counter = -1
        self.changed = asyncio.Event()

    def datachange_notification(self, _node: Any, value: int, _data: Any) -> None:
        self.counter = value
        self.changed.set()


async def rig_nodes(client: Client) -> tuple[Any, int, dict[str, Any]]:
    index = await client.get_namespace_index("urn:drill_sim_ros")
    rig = await client.nodes.objects.get_child(f"{index}:Rig")
    return rig, index, {(await n.read_browse_name()).Name: n for n in await rig.get_children()}


async def connect(url: str) -> Client:
    end = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < end:
        client = Client(url, timeout=5)
        client.session_timeout = 600_000
        try:
            await client.connect()
            _, _, nodes = await rig_nodes(client)
            if await nodes["Status"].read_value() in (1, 2):    # Running, WaitingForClient
                return client
            await client.disconnect()
        except (OSError, asyncio.TimeoutError, ua.UaError):
            pass
        await asyncio.sleep(0.2)
    raise SystemExit(f"the gateway at {url} did not run in {START_TIMEOUT_S} s")


async def by_counters(client: Client, periods: int, events: SampleEvents | None) -> float:
    _, _, nodes = await rig_nodes(client)
    first = await nodes["SampleCounter"].read_value() + 1
    start = time.perf_counter()
    for counter in range(first, first + periods):
        speed = speed_rad_s(await nodes["QuillTorque"].read_value())
        if events is not None:
            events.changed.clear()
        await client.write_values([nodes["SpeedSetpoint"], nodes["CommandCounter"]],
                                  [ua.Variant(speed, DOUBLE), ua.Variant(counter, UINT32)])
        if events is None:
            while await nodes["SampleCounter"].read_value() != counter:
                pass
        else:
            while events.counter != counter:
                await asyncio.wait_for(events.changed.wait(), 10.0)
                events.changed.clear()
    return periods / (time.perf_counter() - start)


async def by_step(client: Client, periods: int) -> float:
    rig, index, nodes = await rig_nodes(client)
    start = time.perf_counter()
    for _ in range(periods):
        speed = speed_rad_s(await nodes["QuillTorque"].read_value())
        await nodes["SpeedSetpoint"].write_value(ua.Variant(speed, DOUBLE))
        await rig.call_method(f"{index}:Step")
    return periods / (time.perf_counter() - start)


async def measure(url: str, periods: int) -> dict[str, float]:
    client = await connect(url)
    try:
        _, _, nodes = await rig_nodes(client)
        await nodes["DriveMode"].write_value(ua.Variant(SPEED_MODE, INT32))    # not timed
        rates = {"counters, SampleCounter polled": await by_counters(client, periods, None)}
        events = SampleEvents()
        _, _, nodes = await rig_nodes(client)
        subscription = await client.create_subscription(1, events)
        await subscription.subscribe_data_change(nodes["SampleCounter"])
        rates["counters, SampleCounter subscribed"] = await by_counters(client, periods, events)
        await subscription.delete()
        rates["method Step"] = await by_step(client, periods)
        return rates
    finally:
        await client.disconnect()


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--periods", type=int, default=2000)
    args = parser.parse_args()
    url = f"opc.tcp://127.0.0.1:{free_port()}/drill_sim/"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    sim = subprocess.Popen([str(BIN / "sim_node"), "--ros-args", "-p", "lockstep:=true",
                            "-p", "lockstep_trigger:=command", "-p", "status_line:=false",
                            "-p", "publish_clock:=false"], **quiet)
    gateway = subprocess.Popen([str(BIN / "opcua_gateway"), "--ros-args", "-p",
                                f"endpoint:={url}"], **quiet)
    try:
        rates = asyncio.run(measure(url, args.periods))
    finally:
        stop(gateway)
        stop(sim)
    for way, rate in rates.items():
        print(f"command-triggered lockstep over OPC UA ({way}), field preset, asyncua client "
              f"in another process: {rate:.0f} periods/s over {args.periods} periods "
              f"({rate / 100.0:.1f}x real time at 100 Hz)")


if __name__ == "__main__":
    main()
