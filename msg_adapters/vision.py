# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Class probabilities <-> vision_msgs (4.1): Classification, LabelInfo.

A Classification holds one ObjectHypothesis per class, `class_id` the class name and `score` its
probability, in the order of the class names. LabelInfo maps the integer ids 0..N-1 to the names
(VisionClass), and carries the decision threshold. vision_msgs reserves the largest id of the
type a pipeline counts its classes in for "UNLABELED": 255 below 255 classes, else 65535. The
class map names it too, and an episode that ends without a recognised object is a
Classification whose first hypothesis is UNLABELED (score 1), followed by the best guess so far.

vision_msgs is optional: HAVE_VISION_MSGS says whether its types import and have their type
support (on the PyPI wheels it is built by tools/build_vision_msgs.sh), and VISION_MSGS_MISSING
says why not. Without it the builders raise AdapterError and the rest of msg_adapters works.
"""
from __future__ import annotations

import math

import numpy as np

from .convert import AdapterError

UNLABELED = "UNLABELED"  # vision_msgs/VisionClass's name for the reserved id


def _load():
    """The vision_msgs message classes, or the reason they cannot be used."""
    try:
        from rosidl_generator_py.import_type_support_impl import UnsupportedTypeSupport
        from vision_msgs.msg import Classification, LabelInfo, ObjectHypothesis, VisionClass
    except ImportError as e:
        return None, f"vision_msgs is not installed ({e}); tools/build_vision_msgs.sh builds it"
    kinds = (Classification, LabelInfo, ObjectHypothesis, VisionClass)
    try:
        for kind in kinds:
            type(kind).__import_type_support__()  # what rclpy does on first use
    except UnsupportedTypeSupport as e:
        return None, (f"vision_msgs has no type support here ({e}): its lib/ must be on "
                      "LD_LIBRARY_PATH when the process starts")
    if any(type(kind)._TYPE_SUPPORT is None for kind in kinds):
        return None, "vision_msgs has no type support here (rosidl_generator_py is missing)"
    return (Classification, LabelInfo, ObjectHypothesis, VisionClass), None


_TYPES, VISION_MSGS_MISSING = _load()
HAVE_VISION_MSGS = _TYPES is not None


def _types():
    if _TYPES is None:
        raise AdapterError(VISION_MSGS_MISSING)
    return _TYPES


def unlabeled_id(n_classes: int) -> int:
    """vision_msgs' id of "UNLABELED" for a pipeline of `n_classes`: 255 below 255, else 65535."""
    return 255 if n_classes < 255 else 65535


def _check_names(names):
    names = [str(n) for n in names]
    if not names:
        raise AdapterError("class names: empty")
    if len(names) >= 65535:
        raise AdapterError(f"class names: {len(names)} classes, vision_msgs ids are uint16 "
                           "with 65535 reserved")
    if any(not n for n in names) or len(set(names)) != len(names):
        raise AdapterError(f"class names must be non-empty and distinct: {names}")
    if UNLABELED in names:
        raise AdapterError(f"class names: {UNLABELED!r} is vision_msgs' name for the reserved id")
    return names


def _check_scores(probabilities, names):
    p = np.asarray(probabilities, dtype=np.float64).ravel()
    if len(p) != len(names):
        raise AdapterError(f"probabilities: {len(p)} values for {len(names)} class names")
    if not np.all(np.isfinite(p)) or np.any(p < 0) or np.any(p > 1):
        raise AdapterError("probabilities must be finite and in [0, 1]")
    return p


def _hypotheses(probabilities, names):
    _, _, ObjectHypothesis, _ = _types()
    names = _check_names(names)
    return [ObjectHypothesis(class_id=n, score=float(s))
            for n, s in zip(names, _check_scores(probabilities, names))]


def classification(probabilities, names, header=None):
    """Probabilities (N,) + class names (N) -> vision_msgs/Classification.

    `header` (std_msgs/Header) is the classified image's, so that consumers can match the two.
    """
    Classification = _types()[0]
    msg = Classification(results=_hypotheses(probabilities, names))
    if header is not None:
        msg.header = header
    return msg


def unknown_classification(header=None, probabilities=None, names=None):
    """The Classification of an episode that ended without a recognised object.

    First hypothesis UNLABELED with score 1; then, when given, the best guess so far (the
    probabilities of `names`, as classification() writes them).
    """
    Classification, _, ObjectHypothesis, _ = _types()
    results = [ObjectHypothesis(class_id=UNLABELED, score=1.0)]
    if probabilities is not None or names is not None:
        if probabilities is None or names is None:
            raise AdapterError("unknown_classification: give both probabilities and names, or neither")
        results += _hypotheses(probabilities, names)
    msg = Classification(results=results)
    if header is not None:
        msg.header = header
    return msg


def classification_scores(msg, names):
    """vision_msgs/Classification -> (N,) float64 scores in the order of `names` (0 where a
    class has no hypothesis), and whether it says UNLABELED. Raises on a class not in names."""
    names = _check_names(names)
    index = {n: i for i, n in enumerate(names)}
    scores, unlabeled = np.zeros(len(names)), False
    for h in msg.results:
        if h.class_id == UNLABELED:
            unlabeled = True
        elif h.class_id in index:
            scores[index[h.class_id]] = h.score
        else:
            raise AdapterError(f"classification: class_id {h.class_id!r} is not one of {names}")
    return scores, unlabeled


def label_info(names, threshold, header=None):
    """Class names + decision threshold -> vision_msgs/LabelInfo (publish it transient local).

    class_map: VisionClass(i, names[i]) for every class, then the reserved id as UNLABELED.
    """
    _, LabelInfo, _, VisionClass = _types()
    names = _check_names(names)
    if not (isinstance(threshold, (int, float)) and math.isfinite(threshold)
            and 0.0 <= threshold <= 1.0):
        raise AdapterError(f"label_info threshold must be a number in [0, 1], got {threshold!r}")
    class_map = [VisionClass(class_id=i, class_name=n) for i, n in enumerate(names)]
    class_map.append(VisionClass(class_id=unlabeled_id(len(names)), class_name=UNLABELED))
    msg = LabelInfo(class_map=class_map, threshold=float(threshold))
    if header is not None:
        msg.header = header
    return msg


def label_info_names(msg):
    """vision_msgs/LabelInfo -> the class names in id order (UNLABELED left out).

    Raises AdapterError unless the ids are 0..N-1, each once.
    """
    pairs = sorted((c.class_id, c.class_name) for c in msg.class_map if c.class_name != UNLABELED)
    if [i for i, _ in pairs] != list(range(len(pairs))):
        raise AdapterError(f"label_info: class ids {[i for i, _ in pairs]} are not 0..N-1")
    return [n for _, n in pairs]
