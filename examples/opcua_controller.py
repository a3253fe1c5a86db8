"""A top-drive controller as a PLC runs it, through opcua_gateway (OPC UA, asyncua only).

    sim_node --ros-args -p lockstep:=true -p lockstep_trigger:=command
    opcua_gateway
    python examples/opcua_controller.py --periods 3000

At start, the drive goes to speed mode (DriveMode, an enumeration: 0 speed, 1 torque). Each
period, like a PLC's cyclic task: read the quill torque of the latest sample, run the
law, write the speed setpoint and CommandCounter = SampleCounter + 1 in one request, and poll
SampleCounter until the gateway says that period's sample is in (docs/hil.md). The law: a PI
on the string torque that lowers the speed setpoint as the torque rises above its nominal.
Nothing here comes from drill_sim_ros: only the OPC UA interface.
"""

import argparse
import asyncio

from asyncua import Client, ua

SETPOINT_RAD_S = 6.0              # about 57 rev/min
NOMINAL_TORQUE_NM = 5000.0      # about the string torque of steady drilling at 57 rpm
KP_RAD_S_PER_NM = 4e-4
KI_RAD_S2_PER_NM = 5e-5
PERIOD_S = 0.01                   # sim_node's publish period (publish_rate_hz 100)
MAX_SPEED_RAD_S = 20.0
WAITING_FOR_SIM = 0               # the rig's Status (RigStatus) before its first sample
SPEED_MODE = 0                    # the rig's DriveMode (DriveModeEnum): speed setpoints


def pi_step(integral_nm_s: float, string_torque_nm: float) -> tuple[float, float]:
    """(speed setpoint rad/s, new integral N m s) answering one torque sample."""
    error_nm = string_torque_nm - NOMINAL_TORQUE_NM
    integral_nm_s = integral_nm_s + error_nm * PERIOD_S
    speed = SETPOINT_RAD_S - KP_RAD_S_PER_NM * error_nm - KI_RAD_S2_PER_NM * integral_nm_s
    return min(max(speed, 0.0), MAX_SPEED_RAD_S), integral_nm_s


async def rig_variables(client: Client, rig: str) -> dict:
    index = await client.get_namespace_index("urn:drill_sim_ros")
    obj = await client.nodes.objects.get_child(f"{index}:{rig}")
    return {(await n.read_browse_name()).Name: n for n in await obj.get_children()}


async def connected(endpoint: str, wait_s: float) -> Client:
    """A client connected to the gateway, retrying for ``wait_s`` (it may still be starting)."""
    loop = asyncio.get_running_loop()
    end = loop.time() + wait_s
    while True:
        client = Client(endpoint, timeout=5)
        try:
            await client.connect()
            return client
        except OSError:
            if loop.time() > end:
                raise SystemExit(f"no OPC UA server at {endpoint} after {wait_s:g} s") from None
            await asyncio.sleep(0.2)


async def run(endpoint: str, periods: int, rig: str, wait_s: float) -> None:
    client = await connected(endpoint, wait_s)
    try:
        v = await rig_variables(client, rig)
        while await v["Status"].read_value() == WAITING_FOR_SIM:   # the first sample is in
            await asyncio.sleep(0.1)
        # the law gives speed setpoints: the drive in speed mode (nothing happens if it is)
        await v["DriveMode"].write_value(ua.Variant(SPEED_MODE, ua.VariantType.Int32))
        counter, integral = await v["SampleCounter"].read_value(), 0.0
        for _ in range(periods):
            speed, integral = pi_step(integral, await v["QuillTorque"].read_value())
            counter = (counter + 1) % 2**32
            await client.write_values(
                [v["SpeedSetpoint"], v["CommandCounter"]],
                [ua.Variant(speed, ua.VariantType.Double),
                 ua.Variant(counter, ua.VariantType.UInt32)])
            while await v["SampleCounter"].read_value() != counter:
                pass
    finally:
        await client.disconnect()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--endpoint", default="opc.tcp://127.0.0.1:4840/drill_sim/")
    parser.add_argument("--periods", type=int, default=3000)
    parser.add_argument("--rig", default="Rig", help="the rig object's BrowseName")
    parser.add_argument("--wait", type=float, default=60.0,
                        help="seconds to retry connecting while the gateway starts")
    args = parser.parse_args()
    asyncio.run(run(args.endpoint, args.periods, args.rig, args.wait))


if __name__ == "__main__":
    main()
