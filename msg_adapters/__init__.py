"""ROS message <-> numpy / view conversions, and nothing else. One error type: AdapterError."""
from .convert import (AdapterError, camera_info, camera_info_to_intrinsics, image_to_metres,
                      metres_to_image, pose_to_camera, pose_to_view, position_to_pose,
                      probabilities_from_msg, probabilities_to_msg, stamp_seconds, view_markers,
                      view_to_pose)

__all__ = ["AdapterError", "camera_info", "camera_info_to_intrinsics", "image_to_metres",
           "metres_to_image", "pose_to_camera", "pose_to_view", "position_to_pose",
           "probabilities_from_msg", "probabilities_to_msg", "stamp_seconds", "view_markers",
           "view_to_pose"]
