# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A parameter a node does not declare (a misspelt key on the command line or in a params file)
stops it from starting, in one line naming it and the closest declared one; ROS's own are let by."""
import sys

import pytest

from conftest import import_ros, run_side_by_side

rclpy = import_ros("rclpy")
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from active_recognition.nodes import UnknownParameterError, declare_parameters  # noqa: E402
from active_recognition.nodes.demo import ros_session  # noqa: E402
from active_recognition.nodes.simulated_camera import PARAMS, SimulatedCameraNode  # noqa: E402

FILES = {  # params files, each with a misspelt key beside good ones
    "recognizer.yaml": "recognizer:\n  ros__parameters:\n    seed: 3\n    max_veiws: 5\n",
    "camera.yaml": "simulated_camera:\n  ros__parameters:\n    index: 2\n    datset: procedural\n",
    "wildcard.yaml": "/**:\n  ros__parameters:\n    noise_scael: 2.0\n",
}
UNKNOWN = [
    ("recognizer", ["-p", "max_veiws:=5"],
     "recognizer: error: unknown parameter 'max_veiws' (did you mean 'max_views'?)"),
    ("recognizer", ["--params-file", "{tmp}/recognizer.yaml"],
     "recognizer: error: unknown parameter 'max_veiws' (did you mean 'max_views'?)"),
    ("recognizer", ["-p", "use_sim_time:=false", "-p", "zzz:=1", "-p", "objcet_size:=2.0"],  # each named
     "recognizer: error: unknown parameter 'objcet_size' (did you mean 'object_size'?); "
     "unknown parameter 'zzz'"),
    ("simulated_camera", ["-p", "idnex:=3"],
     "simulated_camera: error: unknown parameter 'idnex' (did you mean 'index'?)"),
    ("simulated_camera", ["--params-file", "{tmp}/camera.yaml"],
     "simulated_camera: error: unknown parameter 'datset' (did you mean 'dataset'?)"),
    ("simulated_camera", ["--params-file", "{tmp}/wildcard.yaml"],
     "simulated_camera: error: unknown parameter 'noise_scael' (did you mean 'noise_scale'?)"),
]


@pytest.fixture(scope="module")
def starts(tmp_path_factory):
    """Every start of UNKNOWN, side by side: [CompletedProcess]."""
    tmp = tmp_path_factory.mktemp("params")
    for name, text in FILES.items():
        (tmp / name).write_text(text)
    return run_side_by_side([[sys.executable, "-m", f"active_recognition.nodes.{node}", "--ros-args",
                              *(a.format(tmp=tmp) for a in args)] for node, args, _ in UNKNOWN])


@pytest.mark.slow
@pytest.mark.parametrize("case", range(len(UNKNOWN)), ids=[" ".join(a) for _, a, _ in UNKNOWN])
def test_a_node_given_an_unknown_parameter_refuses_to_start_in_one_line(starts, case):
    p = starts[case]
    assert p.returncode == 2 and "Traceback" not in p.stderr, p.stderr
    errors = [line for line in p.stderr.splitlines() if "error:" in line]
    assert errors == [UNKNOWN[case][2]], p.stderr


def test_ros_own_parameters_are_let_by_and_an_unknown_one_is_not():
    ros_own = [Parameter("use_sim_time", value=False),
               Parameter("start_type_description_service", value=True),
               Parameter("qos_overrides./depth/image.publisher.depth", value=2),
               Parameter("index", value=1)]
    with ros_session() as (ctx, executor):
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=ros_own)
        executor.add_node(camera)
        assert camera.get_parameter("index").value == 1
        node = Node("simulated_camera", context=ctx, parameter_overrides=[
            Parameter("index", value=1), Parameter("frame", value="cam"), Parameter("qqq", value=1)])
        executor.add_node(node)  # destroyed with the session
        with pytest.raises(UnknownParameterError) as refused:
            declare_parameters(node, PARAMS)
        assert not node.has_parameter("index")  # refused before any is declared
    assert str(refused.value) == ("unknown parameter 'frame' (did you mean 'frame_id'?); "
                                  "unknown parameter 'qqq'")
