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
