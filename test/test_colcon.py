# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""colcon, as a ROS user builds the package: in a fresh workspace, plain and --symlink-install;
the install space has what ros2 run and ros2 launch look for, and the installed recognizer
starts."""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a colcon build and a node started from its install space

ROOT = Path(__file__).resolve().parents[1]
SKIP = shutil.ignore_patterns(".*", "build", "install", "log", "runs", "__pycache__", "*.egg-info")
INSTALLED = ["lib/active_recognition/recognizer", "lib/active_recognition/simulated_camera",
             "share/active_recognition/package.xml",
             "share/active_recognition/launch/active_recognition.launch.xml",
             "share/active_recognition/config/recognizer.yaml",
             "share/active_recognition/config/simulated_camera.yaml",
             "share/ament_index/resource_index/packages/active_recognition"]


def in_workspace(ws, command, **kwargs):
    """Run a shell command in `ws` with its install space sourced, as a user's terminal would."""
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("AMENT_PREFIX_PATH", None)
    return subprocess.Popen(["bash", "-c", f"set +u; . {ws}/install/setup.sh && {command}"], cwd=ws,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            **kwargs)


@pytest.mark.parametrize("symlink", [False, True], ids=["plain", "symlink-install"])
def test_colcon_builds_and_the_installed_recognizer_starts(tmp_path, symlink):
    shutil.copytree(ROOT, tmp_path / "src" / "active_recognition", ignore=SKIP)
    colcon = Path(sys.executable).with_name("colcon")
    build = subprocess.run([str(colcon), "build", "--event-handlers", "console_direct-"]
                           + ["--symlink-install"] * symlink, cwd=tmp_path, capture_output=True,
                           text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    prefix = tmp_path / "install" / "active_recognition"
    assert [p for p in INSTALLED if not (prefix / p).exists()] == []

    where = in_workspace(tmp_path, "cd / && python -c 'import active_recognition as a; print(a.__file__)'")
    assert where.communicate(timeout=60)[0].strip().startswith(str(tmp_path)), "not the built copy"
    node = in_workspace(tmp_path, f"exec {prefix}/lib/active_recognition/recognizer", start_new_session=True)
    lines, deadline = [], time.monotonic() + 120
    try:
        while time.monotonic() < deadline and node.poll() is None:
            lines.append(node.stdout.readline())
            if "recognizer ready" in lines[-1]:
                break
    finally:
        node.terminate()
        node.wait(timeout=20)
    assert any("recognizer ready: 10 classes" in line for line in lines), "".join(lines)[-3000:]
