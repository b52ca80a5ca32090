# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""vision_msgs built from interfaces/vision_msgs: the real package's type hashes, the adapters'
messages across processes (the publisher: test/vision_publisher.py), and in an MCAP recording.

Needs vision_msgs (tools/build_vision_msgs.sh; the README's test command runs it)."""
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import import_ros, load_benchmark, need_vision_msgs

rclpy = import_ros("rclpy")
need_vision_msgs()
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from mcap_ros2.reader import read_ros2_messages  # noqa: E402
from rclpy.qos import QoSDurabilityPolicy, QoSProfile  # noqa: E402
from std_msgs.msg import Header  # noqa: E402
from vision_msgs.msg import Classification, LabelInfo  # noqa: E402
from vision_publisher import EXPECTED, messages  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.nodes.demo import ros_session, spin_until  # noqa: E402
from active_recognition.nodes.recorder import RELIABLE, Recorder, vision_topics  # noqa: E402
from msg_adapters.definitions import SEPARATOR, message_definition  # noqa: E402

HERE = Path(__file__).resolve().parent
stop_processes = load_benchmark("common").stop_processes
# The RIHS01 hashes of vision_msgs 4.1 as its own build generates them
# (rosidl_generator_type_description/vision_msgs/msg/*.json of a colcon build of the released
# package): what a subscriber of the real package compares on discovery.
REAL = {
    "vision_msgs/msg/Classification":
        "RIHS01_f74db28d0eaef3afb78f48bf2161cd709a1383a0309d3454383b25be11345143",
    "vision_msgs/msg/ObjectHypothesis":
        "RIHS01_51da43cec11c01957a64d1e05a24acd18aae7745ec30b74348ad5f6d634f7f90",
    "vision_msgs/msg/LabelInfo":
        "RIHS01_3d37df4015cdf660cc851c51897f2acd957e1ca6205ba0a99aebffb9406b0783",
    "vision_msgs/msg/VisionClass":
        "RIHS01_1e4a11f0fed50b5623cb8ff26ca0e37952a48a9c074d16f804b44e9164c2037a",
}


def test_the_built_types_hash_as_the_real_vision_msgs():
    from vision_msgs.msg import ObjectHypothesis, VisionClass

    with ros_session() as (ctx, executor):
        node = rclpy.create_node("hashes", context=ctx)
        executor.add_node(node)
        seen = {}
        for kind in (Classification, ObjectHypothesis, LabelInfo, VisionClass):
            name = f"vision_msgs/msg/{kind.__name__}"
            node.create_publisher(kind, f"hash/{kind.__name__}", 1)
            info, = node.get_publishers_info_by_topic(f"hash/{kind.__name__}")
            assert info.topic_type == name
            seen[name] = str(info.topic_type_hash)  # the hash the type support announces
    assert seen == REAL
    # and the type descriptions installed beside the .msg files say the same
    share = Path(sys.modules["vision_msgs"].__file__).parents[4] / "share" / "vision_msgs" / "msg"
    described = json.loads((share / "Classification.json").read_text())["type_hashes"]
    assert {h["type_name"]: h["hash_string"] for h in described}["vision_msgs/msg/Classification"] \
        == REAL["vision_msgs/msg/Classification"]


def test_classification_has_one_hypothesis_per_class_and_reads_back():
    header = Header(frame_id="cam")
    header.stamp.sec, header.stamp.nanosec = 12, 34
    probs = np.array([0.1, 0.7, 0.2], dtype=np.float32)
    msg = ma.classification(probs, ["a", "b", "c"], header)
    assert [h.class_id for h in msg.results] == ["a", "b", "c"]
    assert (msg.header.frame_id, msg.header.stamp.sec, msg.header.stamp.nanosec) == ("cam", 12, 34)
    scores, unlabeled = ma.classification_scores(msg, ["c", "b", "a"])
    np.testing.assert_allclose(scores, probs[::-1], rtol=1e-7)
    assert not unlabeled


def test_an_unknown_end_leads_with_unlabeled_and_keeps_the_best_guess():
    bare = ma.unknown_classification()
    assert [(h.class_id, h.score) for h in bare.results] == [(ma.UNLABELED, 1.0)]
    msg = ma.unknown_classification(Header(frame_id="cam"), [0.4, 0.6], ["a", "b"])
    assert [h.class_id for h in msg.results] == [ma.UNLABELED, "a", "b"]
    scores, unlabeled = ma.classification_scores(msg, ["a", "b"])
    assert unlabeled and scores.tolist() == pytest.approx([0.4, 0.6])


def test_an_unknown_status_ends_unlabeled_with_the_best_known_class():
    """The recognizer's end for status unknown (sensing.unknown_energy): the JSON result keeps the
    best class and its probability, the Classification leads with UNLABELED."""
    from active_recognition.nodes.recognizer_outputs import Outputs
    from active_recognition.runtime.active_recognizer import Observation
    from active_recognition.runtime.controller_commands import End

    sent = {}

    class Publisher:
        def __init__(self, name):
            self.name = name

        def publish(self, msg):
            sent[self.name] = msg

    out = Outputs.__new__(Outputs)  # its publishers without a node
    out.classes, out.vision = ["a", "b"], True
    out.pubs = {name: Publisher(name) for name in ("result", "recognition/result/classification")}
    obs = Observation("unknown", np.array([0.3, 0.7]), "b", 0.61, (0.0, 0.0), True, 4, (0.0, 0.0), 0.5)
    out.end(End(obs, Header(frame_id="object"), {**obs.result(), "travel": 1.5, "elapsed": 9.0}, None))
    assert json.loads(sent["result"].data) == {"status": "unknown", "label": "b",
                                               "probability": pytest.approx(0.7), "entropy": 0.61, "views": 4,
                                               "travel": 1.5, "elapsed": 9.0}
    msg = sent["recognition/result/classification"]
    assert [h.class_id for h in msg.results] == [ma.UNLABELED, "a", "b"] and msg.header.frame_id == "object"


def test_label_info_maps_ids_to_names_and_reserves_unlabeled():
    msg = ma.label_info(["a", "b"], 0.9)
    assert [(c.class_id, c.class_name) for c in msg.class_map] == [(0, "a"), (1, "b"), (255, ma.UNLABELED)]
    assert msg.threshold == pytest.approx(0.9) and ma.label_info_names(msg) == ["a", "b"]
    assert ma.unlabeled_id(254) == 255 and ma.unlabeled_id(255) == 65535
    assert ma.label_info([f"c{i}" for i in range(300)], 0.5).class_map[-1].class_id == 65535


@pytest.mark.parametrize("call,why", [
    (lambda: ma.classification([0.5, 0.5], ["a"]), "2 values for 1 class names"),
    (lambda: ma.classification([0.5, float("nan")], ["a", "b"]), "finite and in"),
    (lambda: ma.classification([1.5, 0.0], ["a", "b"]), "finite and in"),
    (lambda: ma.classification([0.5, 0.5], ["a", "a"]), "non-empty and distinct"),
    (lambda: ma.classification([], []), "class names: empty"),
    (lambda: ma.label_info(["a", ma.UNLABELED], 0.5), "reserved id"),
    (lambda: ma.label_info(["a"], 1.5), "threshold must be a number in"),
    (lambda: ma.label_info(["a"], "0.5"), "threshold must be a number in"),
    (lambda: ma.unknown_classification(None, [1.0], None), "both probabilities and names"),
    (lambda: ma.classification_scores(ma.classification([1.0], ["x"]), ["a"]), "'x' is not one of"),
])
def test_bad_input_is_named(call, why):
    with pytest.raises(ma.AdapterError, match=why):
        call()


def test_without_vision_msgs_the_adapters_still_import_and_say_why():
    # vision_msgs hidden from a fresh interpreter: msg_adapters imports, its builders refuse
    code = ("import sys; sys.modules['vision_msgs'] = None\n"
            "import msg_adapters as ma\n"
            "print(ma.HAVE_VISION_MSGS, ma.image_to_metres(ma.metres_to_image([[1.0]]))[0, 0])\n"
            "try:\n    ma.label_info(['a'], 0.5)\nexcept ma.AdapterError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         cwd=HERE.parent)
    assert out.returncode == 0, out.stderr
    first, reason = out.stdout.splitlines()
    assert first == "False 1.0" and "tools/build_vision_msgs.sh builds it" in reason


@pytest.fixture(scope="module")
def publisher():
    """test/vision_publisher.py in another process, once its LabelInfo has gone out."""
    proc = subprocess.Popen([sys.executable, str(HERE / "vision_publisher.py")], cwd=HERE.parent,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        assert proc.stdout.readline().strip() == "latched", proc.stdout.read()[-3000:]
        yield proc
    finally:
        stop_processes([proc])


def receive(kind, topic, qos, timeout=20.0):
    """The first `kind` on `topic` a fresh subscriber gets, or None."""
    got = []
    with ros_session() as (ctx, executor):
        node = rclpy.create_node("listener", context=ctx)
        executor.add_node(node)
        node.create_subscription(kind, topic, got.append, qos)
        spin_until(executor, lambda: got, timeout)
    return got[0] if got else None


@pytest.mark.slow  # a publisher in another process
def test_a_classification_crosses_processes_intact(publisher):
    msg = receive(Classification, "recognition/classification", 10)
    assert msg is not None, "no Classification from the other process"
    assert msg.header.frame_id == EXPECTED["frame_id"] and msg.header.stamp.sec >= 1
    expected = messages(msg.header.stamp.sec)[0]
    assert msg == expected
    scores, unlabeled = ma.classification_scores(msg, EXPECTED["names"])
    assert scores.tolist() == EXPECTED["probabilities"] and not unlabeled


@pytest.mark.slow  # a publisher in another process
def test_label_info_reaches_a_subscriber_that_starts_late(publisher):
    time.sleep(0.5)  # published well before this subscriber exists
    latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
    msg = receive(LabelInfo, "recognition/label_info", latched)
    assert msg is not None, "the latched LabelInfo did not reach a late subscriber"
    assert ma.label_info_names(msg) == EXPECTED["names"]
    assert msg.threshold == pytest.approx(EXPECTED["threshold"])


@pytest.mark.slow  # a publisher in another process
def test_diagnostics_arrive_intact(publisher):
    msg = receive(DiagnosticArray, "/diagnostics", 10)
    assert msg is not None, "no DiagnosticArray from the other process"
    name, level, message, values = EXPECTED["diagnostic"]
    status, = msg.status
    assert (status.name, ma.level_name(status), status.message) == (name, level, message)
    assert ma.status_values(status) == {"image rate (Hz)": "14.25", "frames refused: encoding": "3",
                                        "active": "true"}
    assert msg.header.stamp.sec >= 1 and msg == messages(msg.header.stamp.sec)[1]


def test_the_definitions_hold_the_nested_types():
    sections = message_definition("vision_msgs/msg/Classification").split(SEPARATOR + "\n")
    assert "ObjectHypothesis[] results" in sections[0]
    assert sorted(s.splitlines()[0] for s in sections[1:]) == [
        "MSG: builtin_interfaces/msg/Time", "MSG: std_msgs/msg/Header",
        "MSG: vision_msgs/msg/ObjectHypothesis"]
    label_info = message_definition("vision_msgs/msg/LabelInfo")
    assert "MSG: vision_msgs/msg/VisionClass\n" in label_info and "uint16 class_id" in label_info


def test_the_recorder_writes_vision_msgs_that_mcap_ros2_decodes(tmp_path):
    path = tmp_path / "vision.mcap"
    topics = {**vision_topics(), "/diagnostics": (DiagnosticArray, RELIABLE)}
    assert set(topics) >= {"recognition/classification", "recognition/label_info"}
    with ros_session() as (ctx, executor):
        node = rclpy.create_node("talker", context=ctx)
        executor.add_node(node)
        recorder = Recorder(node, path, topics)
        pubs = {t: node.create_publisher(kind, t, qos) for t, (kind, qos) in topics.items()}
        assert spin_until(executor, recorder.ready, 10)
        sent = {"recognition/classification": messages(7)[0],
                "recognition/result/classification": ma.unknown_classification(
                    messages(8)[0].header, EXPECTED["probabilities"], EXPECTED["names"]),
                "recognition/label_info": ma.label_info(EXPECTED["names"], EXPECTED["threshold"]),
                "/diagnostics": messages(9)[1]}
        for topic, msg in sent.items():
            pubs[topic].publish(msg)
        assert spin_until(executor, lambda: sum(recorder.counts.values()) == len(sent), 10)
        recorder.close()
    decoded = {m.channel.topic.lstrip("/"): m.ros_msg for m in read_ros2_messages(str(path))}
    assert set(decoded) == {t.lstrip("/") for t in sent}
    for topic, msg in sent.items():  # mcap_ros2's own decoder, from the definitions in the file
        topic = topic.lstrip("/")
        if topic == "diagnostics":
            assert [(s.name, s.level, [(kv.key, kv.value) for kv in s.values])
                    for s in decoded[topic].status] == \
                [(s.name, s.level[0], [(kv.key, kv.value) for kv in s.values]) for s in msg.status]
        elif topic == "recognition/label_info":
            assert [(c.class_id, c.class_name) for c in decoded[topic].class_map] == \
                [(c.class_id, c.class_name) for c in msg.class_map]
        else:
            assert decoded[topic].header.stamp.sec == msg.header.stamp.sec
            assert [(h.class_id, h.score) for h in decoded[topic].results] == \
                [(h.class_id, h.score) for h in msg.results]
