"""ROS message <-> numpy / view conversions, and nothing else. One error type: AdapterError."""
from .convert import (AdapterError, camera_info, image_to_metres, metres_to_image, pose_to_camera,
                      view_markers,
                      pose_to_view, probabilities_from_msg, probabilities_to_msg, view_to_pose)

__all__ = ["AdapterError", "camera_info", "image_to_metres", "metres_to_image", "pose_to_camera",
           "pose_to_view", "probabilities_from_msg", "probabilities_to_msg", "view_markers",
           "view_to_pose"]
