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
