# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""ROS message <-> numpy / view conversions, and nothing else. One error type: AdapterError.

vision_msgs is optional (HAVE_VISION_MSGS, VISION_MSGS_MISSING: see msg_adapters.vision).
"""
from .convert import (AdapterError, camera_info, camera_info_to_intrinsics, image_to_metres,
                      metres_to_image, pose_to_camera, pose_to_view, position_to_pose, position_to_transform,
                      probabilities_from_msg, probabilities_to_msg, seconds_to_stamp, stamp_seconds,
                      transform_to_camera, view_markers, view_to_pose)
from .diagnostics import (LEVELS, diagnostic_array, diagnostic_status, level_name,
                          status_values)
from .vision import (HAVE_VISION_MSGS, UNLABELED, VISION_MSGS_MISSING, classification,
                     classification_scores, label_info, label_info_names,
                     unknown_classification, unlabeled_id)

__all__ = ["AdapterError", "camera_info", "camera_info_to_intrinsics", "image_to_metres",
           "metres_to_image", "pose_to_camera", "pose_to_view", "position_to_pose", "position_to_transform",
           "probabilities_from_msg", "probabilities_to_msg", "seconds_to_stamp", "stamp_seconds",
           "transform_to_camera", "view_markers", "view_to_pose",
           "diagnostic_array", "diagnostic_status", "LEVELS", "level_name", "status_values",
           "classification", "classification_scores", "HAVE_VISION_MSGS", "label_info",
           "label_info_names", "UNLABELED", "unknown_classification", "unlabeled_id",
           "VISION_MSGS_MISSING"]
