# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Plain key/values and a level <-> diagnostic_msgs (DiagnosticStatus, DiagnosticArray).

Levels are OK, WARN, ERROR and STALE (diagnostic_msgs/DiagnosticStatus's byte constants 0-3);
values are strings on the wire: floats are written with 6 significant digits, booleans as
true/false, everything else with str().
"""
from __future__ import annotations

import math
import numbers
from collections.abc import Mapping

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from .convert import AdapterError

LEVELS = {"OK": 0, "WARN": 1, "ERROR": 2, "STALE": 3}


def level_byte(level) -> bytes:
    """'OK' / 'WARN' / 'ERROR' / 'STALE' or 0-3 -> the byte DiagnosticStatus.level holds."""
    if isinstance(level, (bytes, bytearray)) and len(level) == 1:
        level = level[0]
    if isinstance(level, str):
        if level.upper() not in LEVELS:
            raise AdapterError(f"diagnostic level {level!r}: use one of {', '.join(LEVELS)}")
        level = LEVELS[level.upper()]
    if isinstance(level, bool) or not isinstance(level, numbers.Integral) or level not in LEVELS.values():
        raise AdapterError(f"diagnostic level {level!r}: use one of {', '.join(LEVELS)} (0-3)")
    return bytes([int(level)])


def level_name(status: DiagnosticStatus) -> str:
    """DiagnosticStatus -> 'OK' / 'WARN' / 'ERROR' / 'STALE'."""
    value = status.level[0] if isinstance(status.level, (bytes, bytearray)) else int(status.level)
    names = {v: k for k, v in LEVELS.items()}
    if value not in names:
        raise AdapterError(f"diagnostic level {value}: not one of {', '.join(LEVELS)} (0-3)")
    return names[value]


def value_text(value) -> str:
    """A diagnostic value as the string it travels as."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return format(value, ".6g") if math.isfinite(value) else str(value)
    return str(value)


def diagnostic_status(name: str, level, message: str = "", values: Mapping | None = None,
                      hardware_id: str = "") -> DiagnosticStatus:
    """A name, a level, a one-line message and {key: value} -> diagnostic_msgs/DiagnosticStatus.

    The keys keep the mapping's order. Raises AdapterError on an empty name or key.
    """
    if not isinstance(name, str) or not name:
        raise AdapterError(f"diagnostic status name must be a non-empty string, got {name!r}")
    values = dict(values or {})
    bad = [k for k in values if not isinstance(k, str) or not k]
    if bad:
        raise AdapterError(f"diagnostic status {name!r}: keys must be non-empty strings, got {bad}")
    return DiagnosticStatus(level=level_byte(level), name=name, message=str(message),
                            hardware_id=str(hardware_id),
                            values=[KeyValue(key=k, value=value_text(v)) for k, v in values.items()])


def diagnostic_array(statuses, stamp=None) -> DiagnosticArray:
    """DiagnosticStatus messages -> diagnostic_msgs/DiagnosticArray (for /diagnostics)."""
    msg = DiagnosticArray(status=list(statuses))
    if stamp is not None:
        msg.header.stamp = stamp
    return msg


def status_values(status: DiagnosticStatus) -> dict:
    """DiagnosticStatus -> {key: value string}, in the message's order."""
    return {kv.key: kv.value for kv in status.values}
