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


def declare_parameters(node, params):
    """Declare {name: (default, type, description)} with descriptors; return their values."""
    from rcl_interfaces.msg import ParameterDescriptor

    for name, (default, kind, text) in params.items():
        node.declare_parameter(name, default, ParameterDescriptor(type=kind, description=text))
    return {name: node.get_parameter(name).value for name in params}


def run_node(node_class, args=None):
    """The standard node main(): init, spin until Ctrl-C or shutdown, clean up."""
    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=args)
    node = None
    try:
        node = node_class()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
