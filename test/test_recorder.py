# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""MCAP recording: complete message definitions, and a recorded demo read back by mcap_ros2."""
import re
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from conftest import import_ros

rclpy = import_ros("rclpy")
from mcap.reader import make_reader  # noqa: E402
from mcap.records import Schema  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from mcap_ros2.reader import read_ros2_messages  # noqa: E402
from rclpy.publisher import Publisher  # noqa: E402
from rclpy.serialization import serialize_message  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.nodes.demo import run_demo  # noqa: E402
from active_recognition.nodes.recorder import Recorder, TOPICS, check_path, recorded_topics, type_name, \
    vision_topics  # noqa: E402
from msg_adapters.definitions import SEPARATOR, message_definition  # noqa: E402


def test_the_ros_page_names_every_topic_a_recording_holds():
    section = (Path(__file__).parents[1] / "docs" / "ros.md").read_text().split("## Recording and viewing a run")[1]
    vision = ("recognition/classification", "recognition/result/classification", "recognition/label_info")
    assert set(vision_topics()) <= set(vision)  # the names below, where vision_msgs can be used
    for topic in {*recorded_topics(), *vision}:
        assert f"`{topic}`" in section, topic


def test_a_definition_holds_the_type_and_every_type_it_uses_once():
    text = message_definition("sensor_msgs/msg/CameraInfo")
    sections = text.split(SEPARATOR + "\n")
    assert "float64[9]  k" in sections[0] and "RegionOfInterest roi" in sections[0]
    names = [s.splitlines()[0] for s in sections[1:]]
    assert sorted(names) == ["MSG: builtin_interfaces/msg/Time", "MSG: sensor_msgs/msg/RegionOfInterest",
                             "MSG: std_msgs/msg/Header"]


@pytest.mark.parametrize("topic", sorted(TOPICS))
def test_an_independent_decoder_reads_rclpy_bytes_with_our_definition(topic):
    kind = TOPICS[topic][0]
    msg = kind()
    if kind.__name__ == "Image":
        msg = ma.metres_to_image(np.arange(12, dtype=np.float32).reshape(3, 4), None, "cam")
    elif kind.__name__ == "MarkerArray":
        msg = ma.view_markers([(0.3, 1.2), (0.5, 2.0)], 1.5, "object")
    elif kind.__name__ == "String":
        msg.data = "chair"
    schema = Schema(id=1, name=type_name(kind), encoding="ros2msg",
                    data=message_definition(type_name(kind)).encode())
    decode = DecoderFactory().decoder_for("cdr", schema)
    decoded = decode(serialize_message(msg))
    if kind.__name__ == "Image":
        assert (decoded.height, decoded.width, decoded.encoding) == (3, 4, "32FC1")
        assert decoded.header.frame_id == "cam"
    elif kind.__name__ == "MarkerArray":
        assert len(decoded.markers) == len(msg.markers) and decoded.markers[0].ns == msg.markers[0].ns
        assert decoded.markers[-1].pose.position.x == pytest.approx(msg.markers[-1].pose.position.x)
    elif kind.__name__ == "String":
        assert decoded.data == "chair"


@pytest.mark.parametrize("name,why", [("no/such/Type", "expected package/msg/Type"),
                                      ("sensor_msgs/msg/NoSuchType", "no share/sensor_msgs/msg/NoSuchType.msg")])
def test_an_unknown_type_is_named(name, why):
    with pytest.raises(ma.AdapterError, match=why):
        message_definition(name)


@pytest.mark.parametrize("path,why", [("run.bag", "ending in .mcap"), ("missing/run.mcap", "does not exist")])
def test_a_bad_record_path_is_named(tmp_path, path, why):
    with pytest.raises(ValueError, match=f"record: .*{why}"):
        check_path(tmp_path / path)


def test_the_demo_refuses_a_bad_record_path_before_any_node_starts(tmp_path, monkeypatch):
    import active_recognition.nodes.demo as demo
    monkeypatch.setattr(demo, "ros_session", lambda *args: pytest.fail("a ROS session started"))
    with pytest.raises(ValueError, match="record: .*must be a file name ending in .mcap"):
        run_demo(objects=1, record=str(tmp_path / "run.txt"), out=lambda line: None)


@pytest.mark.slow  # a node process of its own: seconds
def test_the_node_stopped_by_ctrl_c_writes_its_recording_and_says_so_cleanly(tmp_path):
    path = tmp_path / "run.mcap"
    p = subprocess.Popen([sys.executable, "-m", "active_recognition.nodes.recognizer", "--ros-args",
                          "-p", f"record:={path}"], stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not list(tmp_path.glob(".run.mcap.*")) and time.monotonic() < deadline and p.poll() is None:
            time.sleep(0.2)
        time.sleep(1.0)  # the timers and subscriptions up
        hidden = [f.name for f in tmp_path.glob(".run.mcap.*")]
        p.send_signal(signal.SIGINT)
        err = p.communicate(timeout=30)[1]
    finally:
        p.kill()
    assert p.returncode == 0 and path.is_file(), err
    assert "recorded " in err and "Failed to publish" not in err and "Traceback" not in err, err
    said = re.search(r"`(\.run\.mcap\.[^`]*\.tmp)`", (Path(__file__).parents[1] / "docs" / "ros.md").read_text())
    pattern = re.sub(r"<[a-z]+>", r"\\d+", re.escape(said.group(1)))  # <pid> -> digits
    assert len(hidden) == 1 and re.fullmatch(pattern, hidden[0]), (hidden, said.group(1))  # as ros.md names it


def test_a_recorded_demo_holds_every_message_the_loop_published(tmp_path, monkeypatch):
    published, images = Counter(), {}
    publish = Publisher.publish

    def counting(self, msg):
        published[self.topic_name] += 1
        if self.topic_name == "/depth/image":
            images[(msg.header.stamp.sec, msg.header.stamp.nanosec)] = ma.image_to_metres(msg)
        return publish(self, msg)

    monkeypatch.setattr(Publisher, "publish", counting)
    write = Recorder.on_message

    def slow(self, topic, channel, data):  # the last episode's end reaches the file late
        if topic.startswith("/recognition/result"):
            time.sleep(0.1)
        return write(self, topic, channel, data)

    monkeypatch.setattr(Recorder, "on_message", slow)
    path = tmp_path / "run.mcap"
    summary = run_demo(objects=2, seed=1, out=lambda line: None, record=str(path))
    assert summary["answered"] == 2
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]  # no temporary file left

    recorded, first_image = Counter(), None
    for m in read_ros2_messages(str(path)):
        recorded[m.channel.topic] += 1
        if m.channel.topic == "/depth/image" and first_image is None:
            first_image = m.ros_msg
    loop = {"/depth/image", "/depth/camera_info", "/camera/pose", "/next_view", "/recognition/label",
            "/recognition/probabilities", "/recognition/result", "/recognition/views",
            "/recognition/classes"}
    vision = {"/" + t for t in vision_topics()}  # where vision_msgs can be had (in CI: built)
    assert loop | vision <= set(recorded) <= loop | vision | {"/diagnostics"}
    assert recorded == Counter({t: n for t, n in published.items() if t in loop | vision}) + \
        Counter({"/diagnostics": recorded["/diagnostics"]})
    assert recorded["/recognition/result"] == 2 and recorded["/recognition/classes"] == 1
    if vision:  # a Classification per classified image, decoded without this package
        classified = [m.ros_msg for m in read_ros2_messages(str(path), topics=["/recognition/classification"])]
        assert len(classified) == recorded["/recognition/probabilities"] >= 2
        assert classified[0].header.frame_id == first_image.header.frame_id
        assert abs(sum(h.score for h in classified[0].results) - 1) < 1e-4
        assert recorded["/recognition/result/classification"] == 2
    stamp = (first_image.header.stamp.sec, first_image.header.stamp.nanosec)
    np.testing.assert_array_equal(ma.image_to_metres(first_image), images[stamp])

    with open(path, "rb") as f:  # the ros2 profile as rosbag2 writes it
        reader = make_reader(f)
        header, summary = reader.get_header(), reader.get_summary()
    assert header.profile == "ros2"
    assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    assert all("offered_qos_profiles" in c.metadata for c in summary.channels.values())
    schema = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
    assert schema["/depth/image"] == "sensor_msgs/msg/Image"
    assert schema["/recognition/views"] == "visualization_msgs/msg/MarkerArray"
