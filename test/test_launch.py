# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The launch files as a ROS user runs them: `ros2 launch` starts the nodes, the loop closes, a
goal sent with `ros2 action send_goal` ends recognized, `ros2 param`, `ros2 topic echo` and
`ros2 lifecycle` answer; a wrong argument is refused by launch with its name. Beside them, quick
checks that the files name only what the package builds and installs, and remap only names the
node has."""
import os
import re
import runpy
import shlex
import xml.etree.ElementTree as ET
from pathlib import Path
from unittest import mock

import pytest
import yaml
from ros2_cli import RECOGNIZE, Running, nodes_up, ros2, until

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.model import checkpoint
from active_recognition.options.camera_params import SimulatedCameraParameters
from active_recognition.options.flags_and_parameters import parameters
from active_recognition.options.recognizer_params import RecognizerParameters

ROOT = Path(__file__).resolve().parents[1]
LAUNCH = ROOT / "launch" / "active_recognition.launch.xml"
REAL = ROOT / "launch" / "real_camera.launch.xml"
SHARE = "$(find-pkg-share active_recognition)/"
NAMES = {  # the topics each node has, as remap can name them
    "recognizer": {"depth/image", "depth/camera_info", "camera/pose", "next_view",
                   "recognition/probabilities", "recognition/classes", "recognition/label",
                   "recognition/result", "recognition/views"},
    "simulated_camera": {"next_view", "depth/image", "depth/camera_info", "camera/pose"},
}


def setup_kwargs():
    """What setup.py hands to setuptools.setup (run from the package root, as colcon does)."""
    captured, cwd = {}, os.getcwd()
    with mock.patch("setuptools.setup", lambda **kwargs: captured.update(kwargs)):
        try:
            os.chdir(ROOT)  # its globs are relative
            runpy.run_path(str(ROOT / "setup.py"))
        finally:
            os.chdir(cwd)
    return captured


def installed(kwargs):
    """{install path relative to the prefix: source path} of setup.py's data_files."""
    return {f"{dest}/{Path(src).name}": src for dest, srcs in kwargs["data_files"] for src in srcs}


def launch_problems(path, kwargs):
    """Each executable, package and parameter file the launch file names that does not exist."""
    root = ET.parse(path).getroot()
    package = ET.parse(ROOT / "package.xml").getroot().findtext("name")
    executables = {s.split("=")[0].strip() for s in kwargs["entry_points"]["console_scripts"]}
    files = installed(kwargs)
    args = {a.get("name"): a.get("default") for a in root.findall("arg")}
    problems = []
    for node in root.iter("node"):
        where = f"node {node.get('name')!r}"
        if node.get("pkg") != package:
            problems.append(f"{where}: package {node.get('pkg')!r} is not {package!r}")
        if node.get("exec") not in executables:
            problems.append(f"{where}: executable {node.get('exec')!r} is not a console script")
        for remap in node.iter("remap"):
            if remap.get("from") not in NAMES.get(node.get("exec"), ()):
                problems.append(f"{where}: remaps {remap.get('from')!r}, which it does not have")
        for env in node.iter("env"):
            value = re.sub(r"\$\(var (\w+)\)", lambda m: args.get(m.group(1)) or "", env.get("value", ""))
            relative = value[len(SHARE):]
            if value.startswith(SHARE) and (f"share/{package}/{relative}" not in files
                                            or not (ROOT / relative).is_file()):
                problems.append(f"{where}: {env.get('name')} names {relative!r}, which setup.py "
                                f"does not install")
        for param in node.iter("param"):
            if param.get("from") is None:  # name and value: node_parameters checks those
                continue
            source = re.sub(r"\$\(var (\w+)\)", lambda m: args.get(m.group(1)) or "", param.get("from", ""))
            if not source.startswith(SHARE):
                problems.append(f"{where}: parameter file {source!r} is not in the package's share")
                continue
            relative = source[len(SHARE):]
            if f"share/{package}/{relative}" not in files or not (ROOT / relative).is_file():
                problems.append(f"{where}: parameter file {relative!r} is not installed by setup.py")
            elif node.get("name") not in yaml.safe_load((ROOT / relative).read_text()):
                problems.append(f"{where}: {relative} has no section for this node's name")
    return problems


def test_launch_file_starts_both_nodes_with_their_installed_parameter_files():
    kwargs = setup_kwargs()
    root = ET.parse(LAUNCH).getroot()
    assert root.tag == "launch"
    assert sorted(n.get("exec") for n in root.iter("node")) == ["recognizer", "simulated_camera"]
    assert launch_problems(LAUNCH, kwargs) == []
    assert "share/active_recognition/launch/active_recognition.launch.xml" in installed(kwargs)


@pytest.mark.parametrize("change,problem", [
    (('exec="recognizer"', 'exec="recogniser"'), "executable 'recogniser' is not a console script"),
    (('pkg="active_recognition" exec="recognizer"', 'pkg="other" exec="recognizer"'), "package 'other'"),
    (("config/recognizer.yaml", "config/missing.yaml"), "'config/missing.yaml' is not installed"),
    (("config/recognizer.yaml", "config/simulated_camera.yaml"), "no section for this node's name"),
])
def test_a_launch_file_naming_what_does_not_exist_is_caught(tmp_path, change, problem):
    bad = tmp_path / "bad.launch.xml"
    bad.write_text(LAUNCH.read_text().replace(*change))
    assert any(problem in p for p in launch_problems(bad, setup_kwargs())), problem


def test_the_real_camera_launch_file_starts_the_recognizer_alone_remapped_to_a_realsense():
    kwargs = setup_kwargs()
    root = ET.parse(REAL).getroot()
    assert [n.get("exec") for n in root.iter("node")] == ["recognizer"]
    assert launch_problems(REAL, kwargs) == []
    assert "share/active_recognition/launch/real_camera.launch.xml" in installed(kwargs)
    args = {a.get("name"): a.get("default") for a in root.findall("arg")}
    remaps = {r.get("from"): re.sub(r"\$\(var (\w+)\)", lambda m: args[m.group(1)], r.get("to"))
              for r in root.iter("remap")}
    assert remaps["depth/image"] == "/camera/camera/depth/image_rect_raw"
    assert remaps["depth/camera_info"] == "/camera/camera/depth/camera_info"
    assert "fastdds_large_frames.xml" in REAL.read_text()  # the camera-side transport note


@pytest.mark.parametrize("change,problem", [
    (('from="depth/image"', 'from="depth/imgae"'), "remaps 'depth/imgae', which it does not have"),
])
def test_a_remap_of_a_name_the_node_lacks_is_caught(tmp_path, change, problem):
    bad = tmp_path / "bad.launch.xml"
    bad.write_text(REAL.read_text().replace(*change))
    assert any(problem in p for p in launch_problems(bad, setup_kwargs())), problem


def test_the_shipped_fastdds_profile_is_installed_and_set_for_the_simulated_camera(tmp_path):
    kwargs = setup_kwargs()
    assert "share/active_recognition/config/fastdds_large_frames.xml" in installed(kwargs)
    env = [e for n in ET.parse(LAUNCH).getroot().iter("node") for e in n.iter("env")]
    assert [e.get("name") for e in env] == ["FASTRTPS_DEFAULT_PROFILES_FILE"]
    bad = tmp_path / "bad.launch.xml"
    bad.write_text(LAUNCH.read_text().replace("fastdds_large_frames.xml", "fastdds_missing.xml"))
    assert any("does not install" in p for p in launch_problems(bad, kwargs))


def substitute(text, args):
    """`text` with the launch frontend's substitutions that these files use performed, as launch
    (Jazzy) performs them: $(var NAME); $(find-pkg-share PKG), left as it is (SHARE); $(equals A B)
    ("true" or "false"); $(if COND A [B]). Arguments are separated by single spaces and nest."""
    def value(i, nested):  # the text from i up to a space or ")" that ends an argument
        out = ""
        while i < len(text) and not (nested and text[i] in " )"):
            if text.startswith("$(", i):
                part, i = substitution(i + 2)
            else:
                part, i = text[i], i + 1
            out += part
        return out, i

    def substitution(i):  # just after "$(": -> (its value, the index after its ")")
        name = re.match(r"[A-Za-z][\w-]*", text[i:]).group(0)
        i += len(name)
        words = []
        while text[i] == " ":
            word, i = value(i + 1, True)
            words.append(word)
        assert text[i] == ")", text
        if name == "var":
            return args[words[0]], i + 1
        if name == "find-pkg-share":
            return f"$(find-pkg-share {words[0]})", i + 1
        if name == "equals":
            return str(words[0] == words[1]).lower(), i + 1
        if name == "if":
            truth = {"true": True, "1": True, "false": False, "0": False}[words[0].lower()]
            return (words[1] if truth else (words[2] if len(words) > 2 else "")), i + 1
        raise AssertionError(f"substitution $({name} ...) is not one the test knows")
    return value(0, False)[0]


def launch_args(path):
    """{name: default} and {name: choices} of a launch file's arguments."""
    root = ET.parse(path).getroot()
    return ({a.get("name"): a.get("default") for a in root.findall("arg")},
            {a.get("name"): [c.get("value") for c in a.iter("choice")] for a in root.findall("arg")})


def node_parameters(path, **given):
    """{node name: {parameter: value}} as each node of the launch file gets them with the
    arguments `given` (the others at their defaults): its parameter files' section for its name,
    then its own name/value parameters, later ones overriding earlier ones (the order launch_ros
    hands them to the node in); a value typed str stays a string, others are read as YAML."""
    defaults, choices = launch_args(path)
    unknown = set(given) - set(defaults)
    assert not unknown, f"no such launch argument: {unknown}"
    for name, value in given.items():
        assert not choices[name] or value in choices[name], f"{name}:={value} is not a choice"
    args = {**defaults, **given}
    out = {}
    for node in ET.parse(path).getroot().iter("node"):
        params = out[node.get("name")] = {}
        for param in node.iter("param"):
            if param.get("from") is not None:
                relative = substitute(param.get("from"), args)[len(SHARE):]
                params.update(yaml.safe_load((ROOT / relative).read_text())[node.get("name")]["ros__parameters"])
            else:
                text = substitute(param.get("value"), args)
                params[param.get("name")] = text if param.get("type") == "str" else yaml.safe_load(text)
    return out


def test_substitute_performs_nested_substitutions_as_launch_does():
    rule = "$(if $(equals $(var objects) modelnet) modelnet10.pt $(var objects).pt)"
    assert substitute(rule, {"objects": "modelnet"}) == "modelnet10.pt"
    assert substitute(rule, {"objects": "twins"}) == "twins.pt"
    assert substitute("$(find-pkg-share p)/config/$(var f).yaml", {"f": "x"}) == "$(find-pkg-share p)/config/x.yaml"
    assert substitute("$(if 0 a)", {}) == "" and substitute("a b $(var x)", {"x": ""}) == "a b "


@pytest.mark.parametrize("objects,root", [("procedural", ""), ("twins", ""), ("modelnet", "/data/ModelNet10")])
def test_objects_shows_the_camera_the_objects_the_model_was_trained_on(objects, root):
    """`objects` sets the camera's dataset and root and the recognizer's checkpoint to that
    dataset's shipped model, as `active-recognition demo --dataset` picks it (model_path with
    no file named); the parameter files themselves (config/*.yaml, generated) are untouched."""
    given = {"objects": objects, "root": root} if root else {"objects": objects}
    params = node_parameters(LAUNCH, **given)
    camera, recognizer = params["simulated_camera"], params["recognizer"]
    assert camera["dataset"] == objects and camera["root"] == root
    # the recognizer's own rule for its checkpoint parameter, against the demo's for the dataset
    model = checkpoint.model_path(recognizer["checkpoint"], "modelnet")
    assert model == checkpoint.model_path("", objects) == checkpoint.shipped(objects) and model.is_file()
    if objects != "modelnet":  # an embedded dataset: the model's classes are the objects'
        shown = open_dataset(objects, None, camera["split"], cache_dir=default_cache_dir())
        assert checkpoint.load_model(model)[1] == list(shown.classes)
    # the rest of each node's parameters is its file's
    for name, file in (("recognizer", "recognizer.yaml"), ("simulated_camera", "simulated_camera.yaml")):
        own = yaml.safe_load((ROOT / "config" / file).read_text())[name]["ros__parameters"]
        changed = {k for k in own if own[k] != params[name][k]}
        assert changed <= {"checkpoint", "dataset", "root", "pose_source", "publish_tf", "publish_pose"}


@pytest.mark.parametrize("source", ["tf", "topic"])
def test_pose_source_sets_where_the_camera_says_it_is_and_where_the_recognizer_reads_it(source):
    defaults, choices = launch_args(LAUNCH)
    assert defaults["pose_source"] == "tf" and choices["pose_source"] == ["tf", "topic"]
    params = node_parameters(LAUNCH, pose_source=source)
    camera, recognizer = params["simulated_camera"], params["recognizer"]
    assert recognizer["pose_source"] == source
    assert (camera["publish_tf"], camera["publish_pose"]) == ((True, False) if source == "tf" else (False, True))


def test_objects_defaults_to_procedural_and_offers_each_shipped_model():
    defaults, choices = launch_args(LAUNCH)
    assert defaults["objects"] == "procedural" and defaults["root"] == ""
    assert choices["objects"] == list(checkpoint.SHIPPED_FOR)
    params = node_parameters(LAUNCH)
    assert params["simulated_camera"]["dataset"] == "procedural"
    assert checkpoint.model_path(params["recognizer"]["checkpoint"], "modelnet") == checkpoint.shipped("procedural")
    # the recognizer's file alone would show it ModelNet10's model (real furniture)
    alone = yaml.safe_load((ROOT / "config" / "recognizer.yaml").read_text())["recognizer"]["ros__parameters"]
    assert checkpoint.model_path(alone["checkpoint"], "modelnet") == checkpoint.shipped("modelnet")
    with pytest.raises(AssertionError, match="not a choice"):
        node_parameters(LAUNCH, objects="shapenet")


@pytest.mark.parametrize("objects", ["procedural", "modelnet"])
def test_every_parameter_the_launch_file_gives_a_node_is_one_it_declares(objects):
    """A node refuses to start on a parameter it does not declare (nodes.declare_parameters)."""
    declared = {"recognizer": set(parameters(RecognizerParameters)),
                "simulated_camera": set(parameters(SimulatedCameraParameters))}
    for name, params in node_parameters(LAUNCH, objects=objects).items():
        assert set(params) - declared[name] == set(), name


def test_a_shipped_models_bare_name_is_that_model_unless_a_file_of_that_name_is_here(tmp_path, monkeypatch):
    for dataset, name in checkpoint.SHIPPED_FOR.items():
        assert checkpoint.model_path(name) == checkpoint.shipped(dataset)
    assert checkpoint.model_path("x/procedural.pt") == Path("x/procedural.pt")  # a path is a path
    monkeypatch.chdir(tmp_path)
    (tmp_path / "twins.pt").write_bytes(b"")
    assert checkpoint.model_path("twins.pt") == Path("twins.pt")  # the file here wins


# ---- the launch files run, as a ROS user types them (the ros2 command line that the set-up builds)


def send_goal(line):
    """`ros2 LINE...` (an action send_goal): (its output, the result's fields)."""
    done = ros2(*line, timeout=240)
    assert done.returncode == 0, done
    assert "Goal finished with status: " in done.stdout, done.stdout[-2000:]
    result = done.stdout[done.stdout.rindex("Result:"):]
    fields = dict(re.findall(r"^\s*(status|views): (\S+)$", result, re.M))
    return done.stdout, fields


def yaml_param(name, value):
    """What `ros2 param get` prints for a value (rclpy's wording per type)."""
    kind = {bool: "Boolean", int: "Integer", float: "Double", str: "String"}[type(value)]
    return f"{kind} value is: {value}"


def quick_start():
    """The README's ROS quick start: the ros2 command lines of its fenced block, split as a shell
    splits them."""
    text = (ROOT / "README.md").read_text()
    block = text[text.index("<!-- ros-quick-start -->"):].split("```")[1]
    lines = [shlex.split(line) for line in block.strip().splitlines()]
    assert all(words[0] == "ros2" for words in lines), lines
    return [words[1:] for words in lines]


@pytest.mark.slow
def test_the_readmes_ros_quick_start_runs_as_written(tmp_path, ros2_daemon):
    """Each line of the README's ROS quick start, verbatim: both nodes up, a goal with feedback
    then a result (recognized), the result on recognition/result, a parameter set (and one out of
    range refused with its range), the lifecycle state; Ctrl-C ends both nodes cleanly."""
    launch_line, echo_line, goal_line, param_line, lifecycle_line = quick_start()
    assert launch_line == ["launch", "active_recognition", "active_recognition.launch.xml"]
    own = yaml.safe_load((ROOT / "config" / "recognizer.yaml").read_text())["recognizer"]["ros__parameters"]
    lo, hi = parameters(RecognizerParameters)["pose_wait"].bounds
    with Running(launch_line, tmp_path / "launch.log") as launch:
        launch.wait_for(r"recognizer ready")
        nodes_up("/recognizer", "/simulated_camera")
        # echo finds the topic's type through the daemon, as topic info does: it must be known there
        until(["topic", "info", "/recognition/result"], r"Publisher count: [1-9]")
        with Running(echo_line, tmp_path / "echo.log") as echo:
            until(["topic", "info", "/recognition/result"], r"Subscription count: [1-9]")
            out, result = send_goal(goal_line)
            assert out.index("Feedback:") < out.index("Result:")
            assert result["status"] == "recognized" and 1 <= int(result["views"]) <= 6
            assert "Goal finished with status: SUCCEEDED" in out
            echo.wait_for(r"---")
            # the JSON, cut at ros2 topic echo's 128 characters (--full-length prints it whole)
            data = yaml.safe_load(echo.text().split("---")[0])["data"]
            assert data.startswith('{"status": "recognized", "label": "') and f'"views": {result["views"]},' in data

        name, value = param_line[3:]
        assert yaml_param(name, own[name]) in ros2("param", "get", "/recognizer", name).stdout
        refused = ros2("param", "set", "/recognizer", "pose_wait", str(hi + 1.0))
        assert "Setting parameter failed" in refused.stderr
        assert f"out of range Min: {float(lo)}, Max: {float(hi)}" in refused.stderr, refused
        assert yaml_param(name, own[name]) in ros2("param", "get", "/recognizer", name).stdout  # kept
        assert "Set parameter successful" in ros2(*param_line).stdout
        assert yaml_param(name, float(value)) in ros2("param", "get", "/recognizer", name).stdout
        until(lifecycle_line, r"^active \[3\]$")
        launch.stop()
    log = launch.text()
    assert "Traceback" not in log, log[-3000:]
    assert re.search(r"\[recognizer-\d+\]: process has finished cleanly", log), log[-3000:]
    assert re.search(r"\[simulated_camera-\d+\]: process has finished cleanly", log), log[-3000:]


@pytest.mark.slow
def test_ros2_launch_arguments_set_the_objects_and_where_the_pose_goes(tmp_path, ros2_daemon):
    """objects:=twins pose_source:=topic: the camera shows the look-alike pairs, the recognizer
    loads twins.pt and reads camera/pose, as the nodes themselves say; a goal ends recognized."""
    with Running(["launch", "active_recognition", "active_recognition.launch.xml", "objects:=twins",
                  "pose_source:=topic"], tmp_path / "launch.log") as launch:
        launch.wait_for(r"recognizer ready")
        nodes_up("/recognizer", "/simulated_camera")
        for node, name, value in (("/recognizer", "checkpoint", "twins.pt"), ("/recognizer", "pose_source", "topic"),
                                  ("/simulated_camera", "dataset", "twins"),
                                  ("/simulated_camera", "publish_pose", True),
                                  ("/simulated_camera", "publish_tf", False)):
            assert yaml_param(name, value) in ros2("param", "get", node, name).stdout, (node, name)
        _, result = send_goal(["action", "send_goal", "/recognize", RECOGNIZE, "{max_views: 3}"])
        assert result["status"] in ("recognized", "unsure", "unknown") and 1 <= int(result["views"]) <= 3


@pytest.mark.parametrize("path,given,said", [
    (LAUNCH, "objects:=shapenet", 'Argument "objects" provided value "shapenet" is not valid. Valid options are: '
                                  "['procedural', 'twins', 'modelnet']"),
    (LAUNCH, "pose_sorce:=topic", "unknown launch argument 'pose_sorce' (did you mean 'pose_source'?)"),
    (REAL, "depth_imgae:=/d", "unknown launch argument 'depth_imgae' (did you mean 'depth_image'?)"),
])
def test_a_wrong_launch_argument_is_refused_by_launch_with_its_name(ros2_daemon, path, given, said):
    """A value outside the choices (launch's own check) or a name the file does not declare
    (launch/check_arguments.launch.py: launch alone would ignore it) ends the launch, no node started."""
    bad = ros2("launch", "active_recognition", path.name, given)
    assert bad.returncode != 0
    assert said in bad.stdout + bad.stderr, bad
    assert "process started" not in bad.stdout + bad.stderr


@pytest.mark.parametrize("path", [LAUNCH, REAL])
def test_the_argument_check_names_every_argument_the_file_declares(path):
    include = ET.parse(path).getroot().find("include")
    assert include.get("file").endswith("/launch/check_arguments.launch.py")
    assert include.find("arg").get("value").split() == list(launch_args(path)[0])


@pytest.mark.parametrize("path", [LAUNCH, REAL])
def test_every_launch_argument_the_docs_name_is_one_the_file_declares(path, ros2_daemon):
    """`ros2 launch --show-args` lists each NAME:= that docs/ros.md and the file's own comment use."""
    shown = ros2("launch", "active_recognition", path.name, "--show-args")
    assert shown.returncode == 0, shown
    declared = set(re.findall(r"^    '(\w+)':", shown.stdout, re.M))
    assert declared == set(launch_args(path)[0])
    named = set(re.findall(rf"{path.name} ((?:\w+:=\S+ ?)+)", (ROOT / "docs" / "ros.md").read_text()
                           + path.read_text()))
    used = {arg.split(":=")[0] for args in named for arg in args.split()}
    assert used and used <= declared, used - declared


@pytest.mark.slow
def test_the_real_camera_launch_file_starts_the_recognizer_alone_on_a_realsenses_topics(tmp_path, ros2_daemon):
    with Running(["launch", "active_recognition", "real_camera.launch.xml", "depth_image:=/my/depth"],
                 tmp_path / "launch.log") as launch:
        launch.wait_for(r"recognizer ready")
        nodes_up("/recognizer")
        assert [re.sub(r"-\d+$", "", p) for p in re.findall(r"\[INFO\] \[([\w-]+)\]: process started",
                                                            launch.text())] == ["recognizer"]
        info = until(["node", "info", "/recognizer"], r"(?s)Subscribers:.*Publishers:").string
        subscribed = info[info.index("Subscribers:"):info.index("Publishers:")]
        assert "/my/depth: sensor_msgs/msg/Image" in subscribed, info
        assert "/camera/camera/depth/camera_info: sensor_msgs/msg/CameraInfo" in subscribed, info
