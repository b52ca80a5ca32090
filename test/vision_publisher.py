# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The other process of test_vision_msgs.py: publishes what msg_adapters builds.

`recognition/label_info` (LabelInfo, transient local) once at start, then prints "latched";
`recognition/classification` (Classification) and `/diagnostics` (DiagnosticArray) at 20 Hz,
the n-th with stamp n s. Everything it publishes comes from EXPECTED, which the test imports.
"""
import rclpy
from builtin_interfaces.msg import Time
from rclpy.executors import ExternalShutdownException
from rclpy.qos import QoSDurabilityPolicy, QoSProfile
from std_msgs.msg import Header

import msg_adapters as ma

EXPECTED = {"names": ["bathtub", "bed", "chair"], "probabilities": [0.125, 0.625, 0.25],
            "threshold": 0.8, "frame_id": "depth_optical",
            "diagnostic": ("recognizer: steps", "WARN", "no image for 2.5 s",
                           {"image rate (Hz)": 14.25, "frames refused: encoding": 3, "active": True})}
LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)


def messages(n):
    """The n-th Classification and DiagnosticArray."""
    header = Header(stamp=Time(sec=n), frame_id=EXPECTED["frame_id"])
    name, level, message, values = EXPECTED["diagnostic"]
    return (ma.classification(EXPECTED["probabilities"], EXPECTED["names"], header),
            ma.diagnostic_array([ma.diagnostic_status(name, level, message, values)],
                                stamp=header.stamp))


def main():
    from diagnostic_msgs.msg import DiagnosticArray
    from vision_msgs.msg import Classification, LabelInfo

    rclpy.init()
    node = rclpy.create_node("vision_publisher")
    labels = node.create_publisher(LabelInfo, "recognition/label_info", LATCHED)
    classes = node.create_publisher(Classification, "recognition/classification", 10)
    diagnostics = node.create_publisher(DiagnosticArray, "/diagnostics", 10)
    labels.publish(ma.label_info(EXPECTED["names"], EXPECTED["threshold"]))
    print("latched", flush=True)
    count = [0]

    def tick():
        count[0] += 1
        classification, array = messages(count[0])
        classes.publish(classification)
        diagnostics.publish(array)

    node.create_timer(0.05, tick)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
