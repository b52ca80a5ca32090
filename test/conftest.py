import importlib
import os
import random

import numpy as np
import pytest

# A private DDS domain per test run, so parallel runs on one machine do not hear each other.
os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(1, 100)))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


def import_ros(name):
    """pytest.importorskip for ROS packages, except in CI (env CI set): there a broken or missing
    ROS install fails the run instead of quietly skipping every test that needs it."""
    if os.environ.get("CI"):
        return importlib.import_module(name)
    return pytest.importorskip(name)
