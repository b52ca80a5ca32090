# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""colcon, as a ROS user builds the package: in a fresh workspace, with the command of
docs/ros.md ("With ROS 2 installed"), plain and --symlink-install; it builds this package and
interfaces/active_recognition_interfaces, the install space has what ros2 run and ros2 launch
look for, the action imports from it, and the installed recognizer starts.

This venv plays the sourced ROS install: its prefix holds the wheels and vision_msgs
(tools/build_interfaces.sh, which the README's test command runs)."""
import os
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import need_vision_msgs

pytestmark = pytest.mark.slow  # a colcon build and a node started from its install space
need_vision_msgs()

ROOT = Path(__file__).resolve().parents[1]
SKIP = shutil.ignore_patterns(".*", "build", "install", "log", "runs", "__pycache__", "*.egg-info")
INSTALLED = ["lib/active_recognition/recognizer", "lib/active_recognition/simulated_camera",
             "share/active_recognition/package.xml",
             "share/active_recognition/launch/active_recognition.launch.xml",
             "share/active_recognition/config/recognizer.yaml",
             "share/active_recognition/config/simulated_camera.yaml",
             "share/ament_index/resource_index/packages/active_recognition"]
ACTION = ["share/active_recognition_interfaces/package.xml",
          "share/active_recognition_interfaces/action/Recognize.action",
          "share/ament_index/resource_index/rosidl_interfaces/active_recognition_interfaces",
          "lib/libactive_recognition_interfaces__rosidl_typesupport_c.so"]
# in the sourced workspace: the action's Python module and the type support libraries it loaded
IMPORT_ACTION = """
from active_recognition_interfaces.action import Recognize
from rclpy.serialization import deserialize_message, serialize_message
goal = Recognize.Goal(object_frame='mug', object_size=0.25, max_views=7)
assert deserialize_message(serialize_message(goal), Recognize.Goal) == goal
print(sys.modules['active_recognition_interfaces'].__file__)
print(*sorted({line.split()[-1] for line in open('/proc/self/maps') if 'libactive_recognition_interfaces__' in line}))
"""

FIND_SERVER = """
import rclpy
from rclpy.action import ActionClient
from active_recognition_interfaces.action import Recognize
rclpy.init()
client = ActionClient(rclpy.create_node('probe'), Recognize, 'recognize')
print('server:', client.wait_for_server(timeout_sec=30))
"""


def documented_build():
    """The colcon build command of docs/ros.md's "With ROS 2 installed", as arguments."""
    section = (ROOT / "docs" / "ros.md").read_text().split("## With ROS 2 installed")[1].split("\n## ")[0]
    line, = [line for line in section.splitlines() if line.startswith("colcon build")]
    return shlex.split(line.split("&&")[0])


def wheel_environment(ws):
    """The build's environment: this venv's prefix as the sourced ROS install (AMENT_PREFIX_PATH,
    CMAKE_PREFIX_PATH), and the CMake arguments a build against the wheels needs
    (tools/build_interfaces.sh passes the same) through a colcon defaults file, so that the
    command stays the documented one."""
    defaults = ws / "wheels.defaults.yaml"
    defaults.write_text(
        "build:\n  cmake-args: [-DBUILD_TESTING=OFF, "
        f"-DCMAKE_PROJECT_INCLUDE={ROOT / 'tools' / 'interfaces_wheels.cmake'}, "
        f"-DPython3_EXECUTABLE={sys.executable}]\n")
    return {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
            "AMENT_PREFIX_PATH": sys.prefix, "CMAKE_PREFIX_PATH": sys.prefix,
            "COLCON_DEFAULTS_FILE": str(defaults)}


def in_workspace(ws, command, **kwargs):
    """Run a shell command in `ws` with its install space sourced, as a user's terminal would."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("AMENT_PREFIX_PATH", None)
    return subprocess.Popen(["bash", "-c", f"set +u; . {ws}/install/setup.sh && {command}"], cwd=ws,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            **kwargs)


def test_the_documented_command_names_the_interface_package():
    command = documented_build()
    assert command[:3] == ["colcon", "build", "--symlink-install"]
    assert "src/active_recognition/interfaces/active_recognition_interfaces" in command
    assert not any("vision_msgs" in arg for arg in command), "a ROS install has the real vision_msgs"


@pytest.mark.parametrize("symlink", [False, True], ids=["plain", "symlink-install"])
def test_colcon_builds_and_the_installed_recognizer_starts(tmp_path, symlink):
    shutil.copytree(ROOT, tmp_path / "src" / "active_recognition", ignore=SKIP)
    command = [arg for arg in documented_build() if symlink or arg != "--symlink-install"]
    command[0] = str(Path(sys.executable).with_name("colcon"))
    build = subprocess.run(command + ["--event-handlers", "console_direct-"], cwd=tmp_path,
                           env=wheel_environment(tmp_path), capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    install = tmp_path / "install"
    assert sorted(p.name for p in install.iterdir() if p.is_dir()) == \
        ["active_recognition", "active_recognition_interfaces"]  # and not the repo's vision_msgs
    prefix = install / "active_recognition"
    assert [p for p in INSTALLED if not (prefix / p).exists()] == []
    assert [p for p in ACTION if not (install / "active_recognition_interfaces" / p).exists()] == []

    where = in_workspace(tmp_path, "cd / && python -c 'import active_recognition as a; print(a.__file__)'")
    assert where.communicate(timeout=60)[0].strip().startswith(str(tmp_path)), "not the built copy"
    action = in_workspace(tmp_path, f"cd / && python -c {shlex.quote('import sys' + IMPORT_ACTION)}")
    out = action.communicate(timeout=60)[0]
    assert action.returncode == 0, out[-3000:]
    module, libraries = out.strip().splitlines()[-2:]
    assert module.startswith(str(install / "active_recognition_interfaces")), module
    assert libraries and all(lib.startswith(str(install)) for lib in libraries.split()), libraries
    node = in_workspace(tmp_path, f"exec {prefix}/lib/active_recognition/recognizer", start_new_session=True)
    lines, deadline = [], time.monotonic() + 120
    try:
        while time.monotonic() < deadline and node.poll() is None:
            lines.append(node.stdout.readline())
            if "recognizer ready" in lines[-1]:
                break
        # it serves the action: a client in another process of the sourced workspace finds it
        client = in_workspace(tmp_path, f"cd / && python -c {shlex.quote(FIND_SERVER)}")
        found = client.communicate(timeout=60)[0]
    finally:
        node.terminate()
        node.wait(timeout=20)
    assert any("recognizer ready: 10 classes" in line for line in lines), "".join(lines)[-3000:]
    assert found.strip().splitlines()[-1:] == ["server: True"], found[-3000:]
