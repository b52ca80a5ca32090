# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""package.xml: valid, in step with setup.py, and every key resolves with rosdep on ROS 2
Jazzy's platform (Ubuntu 24.04), offline: ROS's rules for the keys it names are copied into
test/data/rosdep, the package's own are rosdep/active_recognition.yaml."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from catkin_pkg.package import parse_package

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "test" / "data" / "rosdep"
INTERFACES = ROOT / "interfaces" / "active_recognition_interfaces"
# setup.py's install_requires -> the rosdep key that installs it
KEYS = {"numpy": "python3-numpy", "torch": "python3-torch-pip", "trimesh": "python3-trimesh-pip",
        "embreex": "python3-embreex-pip", "tqdm": "python3-tqdm",
        "matplotlib": "python3-matplotlib", "pyyaml": "python3-yaml", "shapely": "python3-shapely",
        "mapbox-earcut": "python3-mapbox-earcut-pip"}


@pytest.fixture(scope="module")
def rosdep(tmp_path_factory):
    """Run the real rosdep against the package's rules and the copied ones, offline."""
    home = tmp_path_factory.mktemp("rosdep")
    (home / "sources.list.d").mkdir()
    (home / "sources.list.d" / "10-test.list").write_text(
        f"yaml file://{ROOT / 'rosdep' / 'active_recognition.yaml'}\n"
        f"yaml file://{DATA / 'rosdistro_python.yaml'}\n")
    env = {**os.environ, "ROSDEP_SOURCE_PATH": str(home / "sources.list.d"), "ROS_HOME": str(home),
           "ROSDISTRO_INDEX_URL": f"file://{DATA / 'index-v4.yaml'}", "ROS_DISTRO": "jazzy",
           "ROS_PYTHON_VERSION": "3",
           # a fresh machine's: nothing installed from source (--ignore-src skips the keys of the
           # packages found on AMENT_PREFIX_PATH, and the set-up registers the venv's ROS wheels)
           "AMENT_PREFIX_PATH": str(home / "empty")}
    (home / "empty").mkdir()
    exe = Path(sys.executable).with_name("rosdep")

    def run(*args):
        return subprocess.run([str(exe), *args], env=env, capture_output=True, text=True, timeout=120)
    update = run("update", "--rosdistro", "jazzy")
    assert update.returncode == 0, update.stderr
    return run


def test_package_xml_is_valid_and_matches_setup_py():
    package = parse_package(str(ROOT / "package.xml"))
    package.validate()
    setup = (ROOT / "setup.py").read_text()
    assert f'version="{package.version}"' in setup
    assert [str(lic) for lic in package.licenses] == ["Apache-2.0"]
    requires = re.search(r"install_requires=\[(.*?)\]", setup, re.S).group(1)
    names = {re.split(r"[<>=]", r)[0] for r in re.findall(r'"([^"]+)"', requires)} - {"setuptools"}
    exec_keys = {d.name for d in package.exec_depends}
    assert set(KEYS) == names, "a requirement of setup.py has no rosdep key in KEYS"
    assert {KEYS[n] for n in names} <= exec_keys, "package.xml misses a key of setup.py's requirements"
    assert "python3-embreex-pip" in exec_keys and "python3-yaml" in exec_keys


def test_every_key_resolves_on_jazzy(rosdep):
    # the paths of docs/ros.md's rosdep line: the interface package is a key of package.xml that
    # rosdep finds only where its folder is named too (nothing crawls inside a package)
    keys = rosdep("keys", "--from-paths", str(ROOT), str(INTERFACES), "--ignore-src").stdout.split()
    assert "rclpy" in keys and "python3-torch-pip" in keys and "action_msgs" in keys
    assert "active_recognition_interfaces" not in keys
    resolved = rosdep("resolve", *keys, "--os=ubuntu:noble", "--rosdistro=jazzy")
    assert resolved.returncode == 0, resolved.stderr
    # each key gives "#ROSDEP[key]", "#installer", then the packages
    rules = {key: (installer, packages) for key, installer, packages
             in re.findall(r"#ROSDEP\[(\S+)\]\n#(\w+)\n(.+)", resolved.stdout)}
    assert set(rules) == set(keys)
    assert rules["python3-embreex-pip"] == ("pip", "embreex")
    assert rules["python3-torch-pip"] == ("pip", "torch")
    assert rules["python3-yaml"] == ("apt", "python3-yaml")
    assert rules["rclpy"] == ("apt", "ros-jazzy-rclpy")
    # the real vision_msgs on a ROS install: interfaces/vision_msgs (a package inside this one,
    # built only against the PyPI wheels) is not crawled, so it does not hide the key
    assert rules["vision_msgs"] == ("apt", "ros-jazzy-vision-msgs")
    assert rules["diagnostic_msgs"] == ("apt", "ros-jazzy-diagnostic-msgs")
    assert rules["lifecycle_msgs"] == ("apt", "ros-jazzy-lifecycle-msgs")
    assert rules["rosidl_default_generators"] == ("apt", "ros-jazzy-rosidl-default-generators")


def test_without_its_folder_named_the_interface_package_is_an_unresolved_key(rosdep):
    # without its folder named, it is a key like any other, and no rule has it
    keys = rosdep("keys", "--from-paths", str(ROOT), "--ignore-src").stdout.split()
    assert "active_recognition_interfaces" in keys
    resolved = rosdep("resolve", "active_recognition_interfaces", "--os=ubuntu:noble", "--rosdistro=jazzy")
    assert resolved.returncode != 0


def test_the_interface_package_xml_is_valid():
    package = parse_package(str(INTERFACES / "package.xml"))
    package.validate()
    root = parse_package(str(ROOT / "package.xml"))
    assert [str(lic) for lic in package.licenses] == [str(lic) for lic in root.licenses]
    assert [(m.name, m.email) for m in package.maintainers] == [(m.name, m.email) for m in root.maintainers]
    assert {d.name for d in package.build_depends} >= {"action_msgs", "geometry_msgs", "vision_msgs"}
    assert "rosidl_interface_packages" in [g.name for g in package.member_of_groups]
    assert package.get_build_type() == "ament_cmake"


def test_a_key_rosdep_does_not_know_is_reported(rosdep):
    # python3-torch is ROS's key, but Jazzy's Ubuntu has no torch: hence python3-torch-pip
    for key in ("python3-torch", "python3-embreex"):
        resolved = rosdep("resolve", key, "--os=ubuntu:noble", "--rosdistro=jazzy")
        assert resolved.returncode != 0 and f"no rosdep rule for '{key}'" in resolved.stderr
