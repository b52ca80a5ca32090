# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Shared test set-up: a ROS domain of its own per run, one torch thread, the shared dataset
cache, and helpers to load benchmarks and start processes side by side."""
import importlib
import os
import random
import sys

import numpy as np
import pytest

# A private DDS domain per test run, so parallel runs on one machine do not hear each other;
# under pytest-xdist (-n 2) each worker takes its own, 30 apart (workers inherit the run's).
os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(1, 30)))
if os.environ.get("PYTEST_XDIST_WORKER", "").startswith("gw"):
    worker = int(os.environ["PYTEST_XDIST_WORKER"][2:])
    os.environ["ROS_DOMAIN_ID"] = str((int(os.environ["ROS_DOMAIN_ID"]) - 1) % 30 + 1 + 30 * (worker + 1))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
# torch on one thread, here and in every process a test starts (unless OMP_NUM_THREADS says
# otherwise): the tests' tensors are small, and beside the processes a test starts (cameras,
# torchrun workers, commands run side by side) two OpenMP workers a process wait on each other.
# Measured on a busy 2-core machine: test_shipped and test_evaluate in 13-21 s on one thread,
# 52-58 s on two, with twice the CPU time; the recognizer's own step runs on one for that reason.
os.environ.setdefault("OMP_NUM_THREADS", "1")
if "torch" in sys.modules:  # imported before this file: the variable is read at import
    sys.modules["torch"].set_num_threads(int(os.environ["OMP_NUM_THREADS"]))


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


def import_ros(name):
    """pytest.importorskip for ROS packages, except in CI (env CI set): there a broken or missing
    ROS install fails the run instead of quietly skipping every test that needs it."""
    if os.environ.get("CI"):
        return importlib.import_module(name)
    return pytest.importorskip(name)


@pytest.fixture(scope="session")
def tiny_tree(tmp_path_factory):
    """A folder dataset of 2 classes (boxes, cylinders) x 10 sizes: trains and evaluates in
    seconds. The folder split's stable hash puts 1 box and 2 cylinders in test, 17 in train."""
    import trimesh

    root = tmp_path_factory.mktemp("tiny")
    for c, make in (("box", lambda s: trimesh.creation.box(extents=(1, s, 0.5))),
                    ("cylinder", lambda s: trimesh.creation.cylinder(radius=0.3, height=s))):
        (root / c).mkdir()
        for i in range(10):
            make(0.4 + 0.1 * i).export(root / c / f"{c}{i}.stl")
    return root


@pytest.fixture(scope="session")
def dataset_cache():
    """The cache of generated datasets shared by the tests that train or evaluate: the package's
    default (default_cache_dir(), which the shipped-model and node tests read too). Generating
    procedural's 2,000 training shapes takes about 10 s; shared, that happens once per machine
    instead of once per test (each training subprocess inherits the folder through
    ACTIVE_RECOGNITION_CACHE). Tests of the cache itself keep folders of their own."""
    from active_recognition.datasets import default_cache_dir
    return default_cache_dir()


def run_side_by_side(commands, timeout=120, **kwargs):
    """subprocess.run(command, capture_output=True, text=True) for every command, as many at once
    as the machine has cores: the commands the tests start only to see how they refuse bad input
    spend their seconds importing torch and rclpy on one core each, so side by side they take a
    fraction of the time. The CompletedProcess of each, in order."""
    import subprocess
    from concurrent.futures import ThreadPoolExecutor

    def run(command):
        return subprocess.run(command, capture_output=True, text=True, timeout=timeout, **kwargs)
    with ThreadPoolExecutor(max(2, os.cpu_count() or 1)) as pool:
        return list(pool.map(run, commands))


def load_benchmark(name):
    """A script of benchmarks/ as a module (they import their neighbours by plain name)."""
    import sys
    from pathlib import Path

    folder = Path(__file__).resolve().parents[1] / "benchmarks"
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    return importlib.import_module(name)


def sure_or_not(result, confidence):
    """The status an episode that stopped with an answer (a result's dict) must have: recognized
    where its best guess's probability reaches the node's confidence (LabelInfo's threshold, the
    core's `confidence`), else unsure; either way its label is kept."""
    assert result["label"], result
    return "recognized" if result["probability"] >= confidence else "unsure"


def need_vision_msgs():
    """Skip unless vision_msgs is usable here (it has no wheel: tools/build_vision_msgs.sh
    builds it, and the README's test command runs that); in CI (env CI set) fail instead."""
    import msg_adapters as ma

    if not ma.HAVE_VISION_MSGS:
        if os.environ.get("CI"):
            pytest.fail(ma.VISION_MSGS_MISSING)
        pytest.skip(ma.VISION_MSGS_MISSING, allow_module_level=True)


# A node a test makes must be destroyed by the test's end (ros_session destroys those added to its
# executor). One left over keeps its DDS participant alive until the garbage collector happens by:
# it goes on answering discovery in the run's domain, and a latched topic of it reaches the later
# tests of the same worker (seen in CI: a late LabelInfo subscriber heard a leaked recognizer).
_made_nodes = None  # weak references to the nodes made during the running test


def _track_nodes():
    node_module = sys.modules.get("rclpy.node")
    if node_module is None or getattr(node_module.Node, "_tracked", False):
        return
    import weakref

    cls, init, destroy = node_module.Node, node_module.Node.__init__, node_module.Node.destroy_node

    def tracked_init(self, *args, **kwargs):
        init(self, *args, **kwargs)
        if _made_nodes is not None:
            _made_nodes.append((weakref.ref(self), self.get_fully_qualified_name()))

    def tracked_destroy(self, *args, **kwargs):
        self._destroyed = True
        return destroy(self, *args, **kwargs)
    cls.__init__, cls.destroy_node, cls._tracked = tracked_init, tracked_destroy, True


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    global _made_nodes
    _track_nodes()
    _made_nodes = []
    yield
    item._made_nodes, _made_nodes = _made_nodes, None


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item, nextitem):
    yield
    left = [name for ref, name in getattr(item, "_made_nodes", ())
            if ref() is not None and not getattr(ref(), "_destroyed", False)]
    if left:
        pytest.fail(f"nodes made by the test and never destroyed: {', '.join(left)} (add them to "
                    "the ros_session executor, or destroy_node() them)", pytrace=False)


def need_tf2():
    """Skip unless tf2_ros can be imported (it has no wheel: tools/build_interfaces.sh builds it
    from ../shared/deps, and the README's test command runs that); in CI (env CI set) fail."""
    try:
        import tf2_ros  # noqa: F401
    except ImportError as e:
        why = (f"tf2_ros cannot be imported ({e}): bash tools/build_interfaces.sh --geometry2 DIR "
               f"builds it (a ros2/geometry2 jazzy checkout, or ../shared/deps beside the repository)")
        if os.environ.get("CI"):
            pytest.fail(why)
        pytest.skip(why, allow_module_level=True)


@pytest.fixture(scope="module")
def ros2_daemon():
    """The `ros2` command line (test/ros2_cli.py: skipped without it, failed in CI); the daemon
    its commands start in this run's domain is stopped after the module."""
    from ros2_cli import need_ros2, ros2

    need_ros2()
    yield
    ros2("daemon", "stop")
