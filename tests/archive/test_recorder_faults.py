"""mcap_recorder faults: an existing output, a full disk (2 MiB tmpfs)."""

from __future__ import annotations

import os
import subprocess
import time

import pytest
from rclpy.qos import QoSProfile
from std_msgs.msg import UInt8MultiArray

from drill_sim_ros.archive.reader import ArchiveReader
from tests.archive.helpers import BIN, running, wait_for
from tests.archive.ros_fixtures import ros_node

TOPIC = "/drill/test/blob"


def test_recorder_refuses_an_existing_output(tmp_path) -> None:
    keep = tmp_path / "keep.mcap"
    keep.write_bytes(b"precious" * 1000)
    done = subprocess.run([str(BIN / "mcap_recorder"), "-o", str(keep)], capture_output=True,
                          text=True, timeout=30, env=os.environ.copy())
    assert done.returncode == 2 and "--overwrite" in done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert keep.read_bytes() == b"precious" * 1000


def test_recorder_refuses_existing_split_parts(tmp_path) -> None:
    part = tmp_path / "run_0000.mcap"
    part.write_bytes(b"x")
    done = subprocess.run([str(BIN / "mcap_recorder"), "-o", str(tmp_path / "run.mcap"),
                           "--split-duration", "10"], capture_output=True, text=True,
                          timeout=30, env=os.environ.copy())
    assert done.returncode == 2 and "run_0000.mcap exists" in done.stderr
    assert part.read_bytes() == b"x"


@pytest.mark.ros
def test_recorder_on_a_full_disk_stops_and_says_why(small_disk, tmp_path) -> None:
    path = small_disk / "run.mcap"
    log = tmp_path / "recorder.log"
    command = ["mcap_recorder", "-o", str(path), "--topics", TOPIC, "--compression", "none"]
    with running(command, log) as recorder, ros_node("test_blob_publisher") as node:
        pub = node.create_publisher(UInt8MultiArray, TOPIC, QoSProfile(depth=100))
        assert wait_for(lambda: pub.get_subscription_count() > 0, 30), "never subscribed"
        time.sleep(0.3)
        deadline = time.monotonic() + 30
        while recorder.poll() is None and time.monotonic() < deadline:
            pub.publish(UInt8MultiArray(data=os.urandom(20_000)))
            time.sleep(0.005)
        assert recorder.wait(15) == 1
    text = log.read_text()
    assert "Traceback" not in text
    assert text.count("recording stopped: cannot write") == 1
    final = [line for line in text.splitlines() if "recording incomplete" in line]
    assert len(final) == 1 and "No space left on device" in final[0]
    kept = int(final[0].split("; ")[-1].split(" messages kept")[0])
    assert sum(1 for _ in ArchiveReader(path).messages()) == kept > 0
