# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Thin rclpy shells around the core (the only place rclpy is imported)."""
import sys


def declare_parameters(node, params, checks, runtime=()):
    """Declare {name: (default, type, description)} with descriptors; return their values, each
    passed through its validation.Check in `checks` (InputError naming it). Parameters not in
    `runtime` are read-only: the node reads them once, so a later change is refused, not ignored."""
    from rcl_interfaces.msg import ParameterDescriptor

    for name, (default, kind, text) in params.items():
        node.declare_parameter(name, default, ParameterDescriptor(
            type=kind, description=text, read_only=name not in runtime))
    return {name: check_parameter(checks, name, node.get_parameter(name).value)
            for name in params}


def check_parameter(checks, name, value):
    """value as its Check normalises it; InputError naming the parameter otherwise."""
    return checks[name](f"parameter {name}", value) if name in checks else value


def run_node(node_class, args=None):
    """The standard node main(): init, spin until Ctrl-C or shutdown, clean up. A node that cannot
    start (a bad parameter, checkpoint or mesh) says why in one line and exits with status 2."""
    import rclpy
    from rclpy.exceptions import ParameterException
    from rclpy.executors import ExternalShutdownException

    from active_recognition.validation import InputError

    rclpy.init(args=args)
    node = None
    try:
        try:
            node = node_class()
        except (InputError, OSError, ParameterException) as e:
            print(f"{node_class.__name__}: error: {e}", file=sys.stderr)
            return 2
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
