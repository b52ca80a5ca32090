# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The `ros2` command line as a ROS user types it, from tests: a command run to its end, a
command left running (a launch, a node, an echo) and stopped as Ctrl-C stops it, and a command
repeated until what it prints says the graph is ready (discovery takes its time on a busy
machine: the tests wait on that, not on a sleep). Each runs in this Python's environment with
nothing sourced: AMENT_PREFIX_PATH is taken away, so what the set-up registered
(tools/register_package.sh) is what finds the package."""
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROS2 = Path(sys.executable).parent / "ros2"
RECOGNIZE = "active_recognition_interfaces/action/Recognize"


def environment():
    env = {k: v for k, v in os.environ.items() if k != "AMENT_PREFIX_PATH"}
    env["PYTHONUNBUFFERED"] = "1"
    return env


def need_ros2():
    """Skip unless the set-up built the `ros2` command line (tools/build_interfaces.sh); in CI
    (env CI set) fail instead."""
    if not ROS2.is_file():
        why = f"{ROS2} is missing: bash tools/build_interfaces.sh builds the ros2 command line"
        if os.environ.get("CI"):
            pytest.fail(why)
        pytest.skip(why, allow_module_level=True)


def ros2(*args, timeout=60):
    """`ros2 ARGS...` run to its end: its CompletedProcess (text)."""
    return subprocess.run([str(ROS2), *args], capture_output=True, text=True, timeout=timeout,
                          env=environment(), stdin=subprocess.DEVNULL)


class Running:
    """`ros2 ARGS...` (or another command) started in its own process group, its output in a
    file; stop() sends SIGINT, as Ctrl-C does, then SIGKILL to what is left."""

    def __init__(self, args, log, ros2_command=True):
        self.log = Path(log)
        self.out = self.log.open("w")
        self.proc = subprocess.Popen([str(ROS2), *args] if ros2_command else args, stdout=self.out,
                                     stderr=subprocess.STDOUT, env=environment(),
                                     stdin=subprocess.DEVNULL, start_new_session=True)

    def text(self):
        return self.log.read_text()

    def wait_for(self, pattern, timeout=120):
        """Until the output matches `pattern` (its match); fails with the output if the command
        ends or the time runs out first."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            found = re.search(pattern, self.text())
            if found:
                return found
            if self.proc.poll() is not None:
                break
            time.sleep(0.2)
        found = re.search(pattern, self.text())
        assert found, f"{pattern!r} not printed (exit {self.proc.poll()}):\n{self.text()[-3000:]}"
        return found

    def stop(self, timeout=30):
        """SIGINT to the group, as Ctrl-C; SIGKILL after `timeout`; its exit status."""
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGINT)
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
            except ProcessLookupError:
                pass
        self.out.close()
        return self.proc.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def until(args, pattern, timeout=120, each=20):
    """`ros2 ARGS...` repeated until its output (stdout and stderr) matches `pattern`: the
    match; fails with the last output when the time runs out. A call that hangs past `each`
    seconds is stopped and made again: a service call sent before discovery matched its server
    (`ros2 lifecycle get` just after the node came up) waits for its response for ever."""
    end, last = time.monotonic() + timeout, None
    while True:
        try:
            last = ros2(*args, timeout=each)
        except subprocess.TimeoutExpired as e:
            last = f"timed out after {each} s: {e.stdout or ''} {e.stderr or ''}"
        else:
            found = re.search(pattern, last.stdout + last.stderr)
            if found:
                return found
        assert time.monotonic() < end, f"ros2 {' '.join(args)}: {pattern!r} not printed:\n{last}"
        time.sleep(0.5)


def nodes_up(*names, timeout=120):
    """Until `ros2 node list` shows every one of `names`: as the daemon sees the graph, which the
    commands after it ask (`ros2 param` and `ros2 lifecycle` say "Node not found" until it does)."""
    end = time.monotonic() + timeout
    while True:
        listed = set(ros2("node", "list").stdout.split())
        if set(names) <= listed:
            return listed
        assert time.monotonic() < end, f"nodes {set(names) - listed} not up (listed: {listed})"
        time.sleep(0.5)
