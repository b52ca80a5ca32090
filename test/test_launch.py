# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The launch files name only what the package builds and installs, and remap only names the node
has (launch has no wheel, so the files are parsed, not run)."""
import os
import re
import runpy
import xml.etree.ElementTree as ET
from pathlib import Path
from unittest import mock

import pytest
import yaml

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
    args = {a.get("name"): a.get("default") for a in root.iter("arg")}
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
    args = {a.get("name"): a.get("default") for a in root.iter("arg")}
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
