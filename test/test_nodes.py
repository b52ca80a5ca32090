# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Integration: the recognizer and the simulated camera over real topics, with rclpy executors."""
import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest
import torch

from conftest import import_ros, load_benchmark, run_side_by_side, sure_or_not

rclpy = import_ros("rclpy")
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import Image  # noqa: E402
from std_msgs.msg import String  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.datasets import default_cache_dir, open_dataset  # noqa: E402
from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until  # noqa: E402
from active_recognition.nodes.recognizer import Recognizer  # noqa: E402
from active_recognition.nodes.simulated_camera import SimulatedCameraNode  # noqa: E402
from active_recognition.options.recognizer_params import RecognizerParameters  # noqa: E402
from active_recognition.runtime.active_recognizer import ActiveRecognizer  # noqa: E402
from active_recognition.sensing import geometry  # noqa: E402
from active_recognition.sensing.reach import ViewLimits  # noqa: E402
from active_recognition.simulation.depth_sensor import SimulatedCamera  # noqa: E402

common = load_benchmark("common")  # what the ROS benchmarks and these tests share
shipped_checkpoint, stop_processes = common.shipped_checkpoint, common.stop_processes
# the recognizer's default is the ModelNet10 model; these loops show procedural objects
PROCEDURAL = shipped_checkpoint()


@pytest.fixture
def loop():
    with ros_session() as (ctx, executor):
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=[Parameter("index", value=3)])
        recognizer = Recognizer(context=ctx, parameter_overrides=[PROCEDURAL, Parameter("seed", value=7)])
        client = DemoClient(context=ctx)
        for n in (camera, recognizer, client):
            executor.add_node(n)
        assert spin_until(executor, client.reset.service_is_ready, 10)
        yield ctx, executor, camera, recognizer, client


def direct(index, seed):
    """The same episode without ROS: same initial-view draws, renders from the same poses (the
    very first request goes out before any CameraInfo, so at the model's radius), within the
    node's default elevation limits and episode (its stop rule and travel cost)."""
    core = ActiveRecognizer(seed=seed, limits=ViewLimits(0.0, 90.0), episode=RecognizerParameters().episode)
    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=index)
    results, k = [], None
    for _ in range(2):
        core.reset()
        while not core.done:
            pos, rot = ma.pose_to_camera(ma.position_to_pose(*core.requested_pose(k)))
            metres, pos, rot = sim.capture(pos, rot)
            k = sim.k
            obs = core.observe(metres, k, pos, rot)
        results.append((obs.label, obs.views, float(obs.probs.max())))
    return results


def test_closed_loop_matches_the_episode_run_directly(loop):
    ctx, executor, camera, recognizer, client = loop
    over_ros = []
    for _ in range(2):  # the second episode also shows that reset starts a new object
        result = recognize(executor, client)
        assert result is not None
        over_ros.append((result["label"], result["views"], result["probability"]))
    expected = direct(3, seed=7)
    for (label, views, p), (label2, views2, p2) in zip(over_ros, expected):
        assert (label, views) == (label2, views2)
        assert abs(p - p2) < 1e-5


def test_malformed_images_are_rejected_and_the_node_keeps_answering(loop):
    ctx, executor, camera, recognizer, client = loop
    bad = Node("bad_camera", context=ctx)
    executor.add_node(bad)
    pub = bad.create_publisher(Image, "depth/image", qos_profile_sensor_data)
    assert spin_until(executor, lambda: pub.get_subscription_count() > 0, 10)
    recognizer.loop.start(recognizer.now())  # an episode under way, its request not sent
    good = ma.metres_to_image(np.full((128, 128), 0.8, np.float32),
                              recognizer.get_clock().now().to_msg())
    bads = []
    for change in (dict(encoding="rgb8"), dict(data=b"\x00" * 7), dict(height=0, data=b""),
                   dict(step=3)):
        msg = ma.metres_to_image(np.full((64, 64), 0.8, np.float32),
                                 recognizer.get_clock().now().to_msg())  # refused for `change`
        for k, v in change.items():
            setattr(msg, k, v)
        bads.append(msg)
    for msg in bads:
        pub.publish(msg)
        spin_until(executor, lambda: False, 0.05)
    assert spin_until(executor, lambda: recognizer.loop.counts["rejected"] == len(bads), 5)
    assert recognizer.core.episode.steps == 0
    pub.publish(good)  # another resolution (no CameraInfo: the model's field of view) works too
    assert spin_until(executor, lambda: recognizer.core.episode.steps == 1, 5)
    assert recognize(executor, client) is not None  # and a whole episode still works


def test_mesh_change_at_run_time_and_a_bad_mesh_keeps_the_old_one(loop, tmp_path):
    ctx, executor, camera, recognizer, client = loop
    test = open_dataset("procedural", split="test", cache_dir=default_cache_dir())
    result = camera.set_parameters([Parameter("index", value=123)])[0]
    assert result.successful and camera.sim.description.startswith("procedural/test[123]")
    assert test.classes[test.items[123][1]] in camera.sim.description
    (tmp_path / "broken.off").write_text("OFF\n3 1 0\n1 2")
    result = camera.set_parameters([Parameter("mesh", value=str(tmp_path / "broken.off"))])[0]
    assert not result.successful and "broken.off" in result.reason
    assert camera.sim.description.startswith("procedural/test[123]")
    assert recognize(executor, client) is not None


@pytest.mark.slow
def test_nodes_in_separate_processes_close_the_loop():
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    procs = [subprocess.Popen([sys.executable, "-m", f"active_recognition.nodes.{name}"], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
             for name in ("simulated_camera", "recognizer")]
    try:
        with ros_session() as (ctx, executor):
            close_the_loop(ctx, executor)
    finally:
        stop_processes(procs)


def close_the_loop(ctx, executor):
    client = DemoClient(context=ctx)
    executor.add_node(client)
    assert spin_until(executor, client.reset.service_is_ready, 30), "no recognizer service"
    classes = []
    client.create_subscription(String, "recognition/classes",
                               lambda m: classes.append(json.loads(m.data)),
                               QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL))
    result = None
    for _ in range(3):  # discovery between processes can miss the very first request
        result = recognize(executor, client, timeout=10)
        if result is not None:
            break
    assert result is not None and 1 <= result["views"] <= 10
    assert spin_until(executor, lambda: bool(classes), 5) and result["label"] in classes[0]


def test_executor_never_queues_a_callback_twice(loop):
    """Jazzy's MultiThreadedExecutor re-queued waiting tasks (ros2/rclpy#1452); ours does not."""
    ctx, executor, camera, recognizer, client = loop
    submitted = []
    submit = executor._executor.submit
    executor._executor.submit = lambda task: (submitted.append(task), submit(task))[1]
    for _ in range(3):
        assert recognize(executor, client) is not None
    assert submitted and len({id(t) for t in submitted}) == len(submitted)


def test_the_recognizer_loads_the_shipped_modelnet10_model_unless_told_otherwise():
    """A robot sees real objects: an empty `checkpoint` is modelnet10.pt, weights and planner."""
    from active_recognition.model import checkpoint
    from active_recognition.runtime.active_recognizer import choose_planner
    model, classes, ckpt = checkpoint.load_model(checkpoint.shipped("modelnet"))
    with ros_session() as (ctx, executor):
        default = Recognizer(context=ctx)
        procedural = Recognizer(context=ctx, namespace="p", parameter_overrides=[PROCEDURAL])
        for node in (default, procedural):  # ros_session destroys them: left, they go on answering
            executor.add_node(node)         # discovery, the latched label_info heard by later tests
        for node, expected in ((default, model), (procedural, checkpoint.load_model()[0])):
            got = node.core.model.state_dict()
            assert all(torch.equal(got[k], v) for k, v in expected.state_dict().items())
        assert default.core.classes == classes
        assert default.core.planner == choose_planner("auto", model, ckpt)  # its `auto`


def test_demo_on_twins_uses_the_shipped_twins_model_and_its_best_planner():
    from active_recognition.nodes.demo import run_demo
    lines = []
    summary = run_demo(objects=3, seed=2, dataset="twins", out=lines.append)
    assert summary["planner"] == "imitation" and summary["objects"] == 3
    assert summary["answered"] == 3 and summary["rejected_images"] == 0
    assert lines[-1].startswith("planner imitation: accuracy")
    with pytest.raises(ValueError, match="objects must be 1..600"):
        run_demo(objects=0, dataset="twins")


def test_a_realsense_camera_at_a_size_the_model_never_saw_closes_the_loop():
    from active_recognition.nodes.demo import run_demo
    summary = run_demo(objects=2, seed=3, camera="realsense", out=lambda line: None)
    assert summary["camera"] == "640x480" and summary["answered"] == 2


class FakeCamera(Node):
    """Answers each next_view with `image(pose)` and, `pose_delay` seconds later, a pose."""

    def __init__(self, ctx, image, pose=None, pose_delay=0.0, offset=0.0):
        super().__init__("fake_camera", context=ctx)
        self.image, self.pose, self.pose_delay, self.offset = image, pose, pose_delay, offset
        self.pub_image = self.create_publisher(Image, "depth/image", qos_profile_sensor_data)
        if pose is not None:  # a camera without poses does not offer camera/pose
            self.pub_pose = self.create_publisher(PoseStamped, "camera/pose", qos_profile_sensor_data)
        self.create_subscription(PoseStamped, "next_view", self.on_view, 10)
        self.sent, self.queue = 0, []
        self.create_timer(0.005, self.on_timer)

    def on_view(self, msg):
        self.sent += 1
        self.pub_image.publish(ma.metres_to_image(self.image(msg), msg.header.stamp))
        if self.pose is not None:
            self.queue.append((time.monotonic() + self.pose_delay, msg))

    def on_timer(self):
        while self.queue and self.queue[0][0] <= time.monotonic():
            _, request = self.queue.pop(0)
            pose = self.pose(request)
            t = request.header.stamp.sec + request.header.stamp.nanosec * 1e-9 + self.offset
            pose.header.stamp.sec, pose.header.stamp.nanosec = int(t), int(round(t % 1 * 1e9))
            self.pub_pose.publish(pose)


def test_an_empty_scene_ends_with_no_object_after_max_empty_views():
    with ros_session() as (ctx, executor):
        recognizer = Recognizer(context=ctx, parameter_overrides=[PROCEDURAL, Parameter("max_empty_views", value=3)])
        camera = FakeCamera(ctx, lambda pose: np.full((48, 64), np.nan, np.float32))
        client = DemoClient(context=ctx)
        for n in (recognizer, camera, client):
            executor.add_node(n)
        assert spin_until(executor, client.reset.service_is_ready, 10)
        result = recognize(executor, client)
        assert result == {"status": "no_object", "label": "", "probability": 0.0,
                          "entropy": None, "views": 0, "travel": 0.0, "robot_seconds": 0.0,
                          "view_waits": [],
                          "elapsed": pytest.approx(result["elapsed"])}
        assert 0 < result["elapsed"] < 10
        assert recognizer.loop.counts["empty"] == 2 and camera.sent == 3  # asked again twice, then gave up


def test_a_pose_that_arrives_late_but_within_the_tolerance_is_used():
    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=5)
    turn = np.radians(25.0)  # the arm really went 25 degrees further round than asked

    def where(request):
        pos, rot = ma.pose_to_camera(request)
        c, s = np.cos(turn), np.sin(turn)
        rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        return rz @ pos, rz @ rot

    with ros_session() as (ctx, executor):
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            PROCEDURAL, Parameter("pose_tolerance", value=0.2), Parameter("max_views", value=2),
            Parameter("recentre", value=0.0)])  # the view about the frame's own centre
        camera = FakeCamera(ctx, lambda req: sim.capture(*where(req))[0],
                            pose=lambda req: ma.position_to_pose(*where(req)),
                            pose_delay=0.05, offset=0.03)  # stamped 30 ms off, sent 50 ms late
        client = DemoClient(context=ctx)
        for n in (recognizer, camera, client):
            executor.add_node(n)
        assert spin_until(executor, client.reset.service_is_ready, 10)
        recognizer.core.rng = np.random.default_rng(0)
        result = recognize(executor, client)
        assert result["status"] == sure_or_not(result, recognizer.core.confidence)
        initial = recognizer.core.initial_views
        asked = initial[np.random.default_rng(0).integers(len(initial))]
        taken = recognizer.core.views_taken()[0]
        expected = geometry.view_from_position(where(ma.view_to_pose(*asked))[0])[1:]
        np.testing.assert_allclose(taken, expected, atol=1e-5)
        assert abs(taken[1] - asked[1]) > 0.3  # and not the view it asked for


class StreamingCamera(Node):
    """A camera streaming the requested view's image at 50 Hz and never publishing a pose."""

    def __init__(self, ctx, image):
        super().__init__("streaming_camera", context=ctx)
        self.image, self.request = image, None
        self.pub = self.create_publisher(Image, "depth/image", qos_profile_sensor_data)
        self.create_subscription(PoseStamped, "next_view", self.on_view, 10)
        self.create_timer(0.02, self.on_timer)

    def on_view(self, msg):
        self.request = msg

    def on_timer(self):
        if self.request is not None:
            self.pub.publish(ma.metres_to_image(self.image(self.request),
                                                self.get_clock().now().to_msg()))


def test_a_stream_without_poses_faster_than_the_pose_tolerance_is_still_processed():
    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=5)
    with ros_session() as (ctx, executor):
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            PROCEDURAL, Parameter("pose_tolerance", value=0.05), Parameter("max_views", value=3)])
        camera = StreamingCamera(ctx, lambda req: sim.capture(*ma.pose_to_camera(req))[0])
        client = DemoClient(context=ctx)
        for n in (recognizer, camera, client):
            executor.add_node(n)
        assert spin_until(executor, client.reset.service_is_ready, 10)
        result = recognize(executor, client, timeout=15)
        assert result is not None and result["status"] == sure_or_not(result, recognizer.core.confidence)
        assert result["views"] == 3


CANNOT_START = [
    ("recognizer", ["-p", "seed:=-1"], "parameter seed must be an integer from 0 to 4294967295"),
    ("recognizer", ["-p", "max_views:=0"], "parameter max_views must be an integer from 1 to 1000"),
    ("recognizer", ["-p", "object_size:=1"], "expecting type 'DOUBLE'"),  # an integer for a double
    ("recognizer", ["-p", "checkpoint:=/nonexistent.pt"], "/nonexistent.pt: no such file"),
    ("recognizer", ["-p", "object_size:=1e300"], "parameter object_size must be a finite number in"),
    ("recognizer", ["-p", "min_elevation:=50.0", "-p", "max_elevation:=10.0"],
     "min_elevation (50) must not exceed max_elevation (10)"),
    ("simulated_camera", ["-p", "dropout:=1.5"], "parameter dropout must be a finite number in"),
    ("simulated_camera", ["-p", "index:=100000"], "index 100000 is out of range"),
    ("recognizer", ["--params-file", "/nonexistent/params.yaml"], "Couldn't parse params file"),  # a traceback
]


@pytest.fixture(scope="module")
def failed_starts():
    """Every start of CANNOT_START, side by side: {(node, args): CompletedProcess}."""
    done = run_side_by_side([[sys.executable, "-m", f"active_recognition.nodes.{node}", "--ros-args", *args]
                             for node, args, _ in CANNOT_START])
    return {(node, tuple(args)): p for (node, args, _), p in zip(CANNOT_START, done)}


@pytest.mark.slow
@pytest.mark.parametrize("node,args,message", CANNOT_START)
def test_a_node_that_cannot_start_says_why_in_one_line_and_exits_2(failed_starts, node, args, message):
    p = failed_starts[node, tuple(args)]
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr
    errors = [line for line in p.stderr.splitlines() if "error:" in line]
    assert len(errors) == 1 and message in errors[0], p.stderr
    assert errors[0].startswith(f"{node}: error: "), p.stderr  # the executable's name, as ros2 run says it


@pytest.mark.parametrize("node,param", [("recognizer", "max_views:=10  an integer from 1 to 1000"),
                                        ("simulated_camera", "index:=0  an integer >= 0, may change at run time")])
def test_help_lists_the_parameters_instead_of_starting_the_node(node, param):
    p = subprocess.run([sys.executable, "-m", f"active_recognition.nodes.{node}", "--help"],
                       capture_output=True, text=True, timeout=60)  # the node itself would spin on
    assert p.returncode == 0 and p.stdout.startswith(f"usage: ros2 run active_recognition {node} "), p.stderr
    assert f"\n  {param}: " in p.stdout, p.stdout


def test_bad_parameters_at_run_time_are_refused_and_the_node_keeps_its_settings(loop):
    ctx, executor, camera, recognizer, client = loop
    before = recognizer.sensing
    for name, value, reason in [("box_margin", 2.0, "box_margin must be a finite number in [0, 1]"),
                                ("pose_tolerance", float("nan"), "pose_tolerance must be"),
                                ("max_views", 3, "read-only")]:  # read once at start: not ignored
        result = recognizer.set_parameters([Parameter(name, value=value)])[0]
        if reason == "read-only":
            assert not result.successful and reason in result.reason, result.reason
        else:  # outside its descriptor's range: rclpy refuses it, the node logs why in the check's words
            assert not result.successful and "out of range" in result.reason, result.reason
            assert reason in recognizer.refuse.latest[f"parameter {name}"]
    assert recognizer.sensing == before and recognizer.loop.timing.pose_tolerance == 0.05
    assert recognizer.set_parameters([Parameter("object_size", value=2.0)])[0].successful
    assert recognizer.sensing.object_size == 2.0
    assert recognize(executor, client) is not None  # and it still recognises


def test_the_camera_shows_every_split_a_dataset_has():
    """val (where choices are made) and cross (held-out styles) too; it refused them before."""
    with ros_session() as (ctx, executor):
        for split, label in (("val", "procedural/val[0]"), ("cross", "procedural/cross[0]")):
            camera = SimulatedCameraNode(context=ctx, parameter_overrides=[Parameter("split", value=split)])
            assert camera.sim.description.startswith(label), camera.sim.description
            camera.destroy_node()


def test_a_failed_configure_is_logged_and_reported_as_an_error_on_diagnostics():
    from lifecycle_msgs.msg import State
    from rclpy.lifecycle import TransitionCallbackReturn

    with ros_session() as (ctx, executor):
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            Parameter("autostart", value=False), Parameter("checkpoint", value="/nonexistent.pt")])
        executor.add_node(recognizer)  # destroyed at the end of the session
        assert recognizer.state == "unconfigured"  # nothing loaded, nothing opened
        assert recognizer.core is None and recognizer.inputs == []
        assert recognizer.trigger_configure() == TransitionCallbackReturn.FAILURE
        assert recognizer._state_machine.current_state[0] == State.PRIMARY_STATE_UNCONFIGURED
        status = recognizer.diagnostics(time.monotonic()).status[0]
        assert ma.level_name(status) == "ERROR" and "/nonexistent.pt: no such file" in status.message
        values = ma.status_values(status)
        assert values["model"] == "/nonexistent.pt" and values["model loaded"] == "false"
        good = Recognizer(context=ctx, parameter_overrides=[Parameter("autostart", value=False),
                                                            Parameter("max_views", value=0)])
        executor.add_node(good)
        assert good.trigger_configure() == TransitionCallbackReturn.FAILURE
        assert "max_views must be" in str(good.failure)


def test_without_vision_msgs_the_node_says_once_which_outputs_are_off_and_still_works(loop, monkeypatch):
    from rclpy.lifecycle import TransitionCallbackReturn

    from active_recognition.nodes import recognizer_outputs

    ctx, executor, camera, recognizer, client = loop
    monkeypatch.setattr(recognizer_outputs.ma, "HAVE_VISION_MSGS", False)
    monkeypatch.setattr(recognizer_outputs.ma, "VISION_MSGS_MISSING", "vision_msgs is not installed")
    said = []
    monkeypatch.setattr(recognizer.refuse, "once", lambda key, text, warn=False: said.append((key, text)))
    for transition in ("deactivate", "cleanup", "configure", "activate"):
        assert getattr(recognizer, f"trigger_{transition}")() == TransitionCallbackReturn.SUCCESS, transition
    assert said == [("vision_msgs", "vision_msgs outputs off (recognition/classification, "
                                    "recognition/result/classification, recognition/label_info): "
                                    "vision_msgs is not installed")]
    assert not recognizer.outputs.vision and "recognition/classification" not in recognizer.outputs.pubs
    result = recognize(executor, client)
    assert result is not None and result["status"] == sure_or_not(result, recognizer.core.confidence)


def test_an_episode_paused_by_deactivate_goes_on_at_activate(loop):
    from std_srvs.srv import Trigger

    ctx, executor, camera, recognizer, client = loop
    results = []
    client.create_subscription(String, "recognition/result", lambda m: results.append(m.data), 10)
    assert recognizer.on_reset(Trigger.Request(), Trigger.Response()).success  # first view asked
    recognizer.trigger_deactivate()  # before the camera's answer can arrive
    spin_until(executor, lambda: False, 0.5)
    assert recognizer.loop.counts["received"] == 0 and recognizer.core.episode.steps == 0 and not results
    assert recognizer.loop.state == "paused" and recognizer.loop.running
    recognizer.trigger_activate()  # asks for the view again
    assert spin_until(executor, lambda: bool(results), 10)
    result = json.loads(results[0])
    assert result["status"] == sure_or_not(result, recognizer.core.confidence)
    assert recognizer.loop.counts["received"] > 0


def test_a_nodes_own_words_are_those_outside_ros_args():
    from active_recognition.nodes import own_args
    assert own_args(["prog", "--help"]) == ["--help"]
    assert own_args(["prog", "--ros-args", "-p", "x:=1", "--params-file", "/no/such.yaml"]) == []
    assert own_args(["prog", "--ros-args", "-p", "h:=--help", "--", "-h"]) == ["-h"]
