# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Thin rclpy shells around the core (the only place rclpy is imported): messages in, events to the
runtime, its commands out as messages. The nodes layer may import every layer below it; the
recognizer node's imports stay within the runtime, the options and msg_adapters (no training,
evaluation, datasets or simulated camera: test/test_layers.py), and the simulated camera node's
add the datasets and simulation."""
import difflib
import functools
import sys
import time
import traceback

from rclpy.exceptions import InvalidParameterValueException, ParameterNotDeclaredException

from active_recognition.argument_checks import InputError

# parameters rclpy declares on every node itself (its TimeSource, its TypeDescriptionService) and,
# by prefix, those it declares for a publisher or subscription made with QoSOverridingOptions
ROS_PARAMETERS = ("use_sim_time", "start_type_description_service")
ROS_PREFIXES = ("qos_overrides.",)


class UnknownParameterError(ParameterNotDeclaredException):
    """A parameter given to a node that declares none of that name. A ParameterException, which
    run_node reports in one line like an InputError; not an InputError, which the recognizer's
    constructor leaves to configure, where only the declared parameters are checked."""

    def __init__(self, message):
        Exception.__init__(self, message)


def declare_parameters(node, params):
    """Declare {name: options.Param} with descriptors (description, the range where the check bounds
    a number on both sides, read-only unless it may change at run time); return their values, each
    passed through its validation.Check (InputError naming it). A value outside a range is refused
    by rclpy before the node's own callback sees it: it is logged here, as the node logs the others.
    First, a parameter the node was given (`-p`, a params file, parameter_overrides) that neither
    it nor rclpy declares is refused: UnknownParameterError naming it and the closest declared
    name, as a misspelt key would otherwise be ignored without a word."""
    # rclpy (Jazzy) keeps every override the node was given, from the command line, its params
    # files and its constructor, in node._parameter_overrides ({name: Parameter})
    unknown = sorted(name for name in node._parameter_overrides if name not in params
                     and name not in ROS_PARAMETERS and not name.startswith(ROS_PREFIXES)
                     and not node.has_parameter(name))
    if unknown:
        said = []
        for name in unknown:
            close = difflib.get_close_matches(name, [*params, *ROS_PARAMETERS], n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            said.append(f"unknown parameter {name!r}{hint}")
        raise UnknownParameterError("; ".join(said))
    for name, param in params.items():
        try:
            node.declare_parameter(name, param.default, descriptor(param))
        except InvalidParameterValueException:  # out of range: refused below in the check's words
            node.declare_parameter(name, param.default, descriptor(param, ranged=False))
    node.add_pre_set_parameters_callback(functools.partial(log_out_of_range, node, params))
    checks = {name: param.check for name, param in params.items()}
    return {name: check_parameter(checks, name, node.get_parameter(name).value) for name in params}


def descriptor(param, ranged=True):
    """The ROS ParameterDescriptor of an options.Param."""
    from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

    kind = {bool: 1, int: 2, float: 3, str: 4}[param.check.kind]  # rcl_interfaces ParameterType
    d = ParameterDescriptor(type=kind, description=param.description, read_only=param.read_only)
    if ranged and param.bounds is not None:
        lo, hi = param.bounds
        if kind == 2:
            d.integer_range = [IntegerRange(from_value=lo, to_value=hi, step=0)]
        else:
            d.floating_point_range = [FloatingPointRange(from_value=lo, to_value=hi, step=0.0)]
    return d


def log_out_of_range(node, params, changes):
    """rclpy refuses a value outside its descriptor's range before any on-set callback: warn of it
    (node.refuse, per parameter) in the check's words; the list goes on unchanged."""
    refuse = getattr(node, "refuse", None)
    for p in changes:
        param = params.get(p.name)
        if refuse is None or param is None or param.bounds is None or param.read_only:
            continue
        lo, hi = param.bounds
        if isinstance(p.value, (int, float)) and not lo <= p.value <= hi:  # NaN too
            try:
                param.check(f"parameter {p.name}", p.value)
            except InputError as e:
                refuse(f"parameter {p.name}", f"parameter refused: {e}")
    return changes


def check_parameter(checks, name, value):
    """value as its Check normalises it; InputError naming the parameter otherwise."""
    return checks[name](f"parameter {name}", value) if name in checks else value


def guarded(node, callback, on_error=None, throttle=2.0):
    """`callback`, with any exception it raises logged with its traceback (at most once in
    `throttle` seconds per callback) and counted in node.callback_errors, instead of escaping
    into the executor, which would stop the node; returns on_error(*args) then, if given."""
    last, name = [-throttle], getattr(callback, "__name__", None) or repr(callback)

    @functools.wraps(callback)
    def run(*args):
        try:
            return callback(*args)
        except Exception:  # a bug, not an input: the node logs it and goes on
            node.callback_errors = getattr(node, "callback_errors", 0) + 1
            if time.monotonic() - last[0] >= throttle:
                last[0] = time.monotonic()
                node.get_logger().error(f"{name} failed ({node.callback_errors} "
                                        f"so far); going on:\n{traceback.format_exc()}")
            return on_error(*args) if on_error is not None else None
    return run


class Throttled:
    """Warnings throttled per key (a field, a topic), each refusal counted and the latest kept:
    one bad input does not hide another's warning."""

    def __init__(self, logger, period=2.0):
        self.logger, self.period, self.last, self.counts, self.latest = logger, period, {}, {}, {}
        self.told = set()

    def always(self, key, text):
        """A refusal counted and kept as __call__ does, logged every time (a rare one)."""
        self.counts[key] = self.counts.get(key, 0) + 1
        self.latest[key] = text
        self.logger.warn(text)

    def once(self, key, text, warn=False):
        """Log `text` the first time `key` comes (information, or a warning), never again."""
        if key not in self.told:
            self.told.add(key)
            (self.logger.warn if warn else self.logger.info)(text)

    def __call__(self, key, text):
        self.counts[key] = self.counts.get(key, 0) + 1
        self.latest[key] = text
        now = time.monotonic()
        if now - self.last.get(key, -self.period) >= self.period:
            self.last[key] = now
            self.logger.warn(f"{text} ({self.counts[key]} so far)")

    def values(self, keys, prefix="parameter "):
        """{"refused KEY": count} of each of `keys` (0 if none) and of each key that starts with `prefix`."""
        return {f"refused {key}": self.counts.get(key, 0) for key in
                (*keys, *sorted(k for k in self.counts if k.startswith(prefix) and k not in keys))}


def usage(prog, params):
    """What `NAME --help` prints: how to set the node's parameters, and each one's default and range."""
    from active_recognition.options.flags_and_parameters import shown

    lines = [f"usage: ros2 run active_recognition {prog} [--ros-args -p NAME:=VALUE ...]",
             "parameters (docs/options.md; config/*.yaml):"]
    for n, p in params.items():
        value = f'"{p.default}"' if isinstance(p.default, str) else shown(p.default)
        lines.append(f"  {n}:={value}  {p.check.allowed()}{'' if p.read_only else ', may change at run time'}: "
                     f"{p.description}")
    return "\n".join(lines)


def own_args(argv):
    """The words of `argv` (after the program's name) outside ROS's: before any --ros-args, and
    after a `--` that ends one. Read by hand: rclpy's remove_ros_args parses the ROS arguments
    too, and so raises on a bad --params-file before rclpy.init can report it in one line."""
    words, ros = [], False
    for word in argv[1:]:
        if word == "--ros-args":
            ros = True
        elif word == "--" and ros:
            ros = False
        elif not ros:
            words.append(word)
    return words


def run_node(node_class, args=None, name=None, params=None):
    """The standard node main(): init, spin until Ctrl-C or shutdown, clean up. A node that cannot
    start (a bad parameter, checkpoint or mesh) says why in one line, `NAME: error: ...` (NAME the
    executable's, as `ros2 run` calls it), and exits with status 2. `-h` or `--help` outside
    --ros-args prints `params` ({name: options.Param}) instead of starting the node."""
    prog = name or node_class.__name__
    if params is not None and {"-h", "--help"} & set(own_args(sys.argv if args is None else args)):
        print(usage(prog, params))
        return 0
    import rclpy
    from rclpy.exceptions import ParameterException
    from rclpy.executors import ExternalShutdownException

    from active_recognition.argument_checks import InputError

    interrupt_once()
    try:
        rclpy.init(args=args)
    except Exception as e:  # RCLError: a --params-file that is missing or not YAML, a bad --ros-args
        print(f"{prog}: error: {' '.join(str(e).split())}", file=sys.stderr)
        return 2
    node = None
    try:
        try:
            node = node_class()
        except (InputError, OSError, ParameterException) as e:
            print(f"{prog}: error: {e}", file=sys.stderr)
            return 2
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except Exception:  # SIGTERM shuts the context down mid-spin, which rclpy may raise as an RCLError
        if rclpy.ok():
            raise
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


def interrupt_once():
    """Ctrl-C raises KeyboardInterrupt once (the main thread only); later SIGINTs are ignored.
    Ctrl-C on `ros2 launch` reaches its nodes twice, from the terminal and again from launch, and
    the second would otherwise break the node's clean-up. Installed before rclpy.init, whose own
    handler (it wakes the executor) then hands each SIGINT on to this one; SIGTERM still ends it."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return
    seen = []

    def on_interrupt(signum, frame):
        if not seen:
            seen.append(signum)
            raise KeyboardInterrupt
    signal.signal(signal.SIGINT, on_interrupt)
