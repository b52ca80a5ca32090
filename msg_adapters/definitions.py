# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Complete message definitions in the `ros2msg` form rosbag2 stores in MCAP files.

The type's own .msg text first, then every type its fields use (recursively, each once), each
after a line of 80 "=" and a line "MSG: package/msg/Type" (rosbag2's
docs/message_definition_encoding.md). The .msg files come from the message packages' share
folders: under each prefix of AMENT_PREFIX_PATH on a ROS install, and under sys.prefix for the
PyPI wheels.
"""
from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from .convert import AdapterError

SEPARATOR = "=" * 80
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
              "int32", "uint32", "int64", "uint64", "string", "wstring"}


def prefixes():
    """Where message packages are installed, first match wins."""
    ament = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [Path(p) for p in ament] + [Path(sys.prefix)]


def split_type(name):
    """'pkg/msg/Type' or 'pkg/Type' -> ('pkg', 'Type')."""
    parts = name.split("/")
    if len(parts) == 3 and parts[1] == "msg":
        parts = [parts[0], parts[2]]
    if len(parts) != 2 or not all(re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", p) for p in parts):
        raise AdapterError(f"message type {name!r}: expected package/msg/Type")
    return parts[0], parts[1]


def msg_text(package, name, search=None):
    """The text of package/msg/name.msg from the first prefix that has it."""
    for prefix in search or prefixes():
        path = prefix / "share" / package / "msg" / f"{name}.msg"
        if path.is_file():
            return path.read_text(encoding="utf-8")
    where = ", ".join(str(p) for p in search or prefixes())
    raise AdapterError(f"message type {package}/msg/{name}: no share/{package}/msg/{name}.msg "
                       f"under {where} (is {package} installed, and AMENT_PREFIX_PATH set?)")


def field_types(text, package):
    """The message types (package, Type) the fields and constants of a .msg text use, in order."""
    found = []
    for line in text.splitlines():
        tokens = line.split("#", 1)[0].split()
        if not tokens:
            continue
        base = re.sub(r"\[.*\]$", "", tokens[0])  # arrays: Type[], Type[3], Type[<=3]
        base = re.sub(r"<=\d+$", "", base)  # bounded strings: string<=10
        if base in PRIMITIVES:
            continue
        dep = split_type(base) if "/" in base else (package, base)
        if dep not in found:
            found.append(dep)
    return found


def message_definition(type_name, search=None):
    """The complete ros2msg definition of `type_name` ('sensor_msgs/msg/Image')."""
    package, name = split_type(type_name)
    text = msg_text(package, name, search)
    parts, seen = [text.rstrip("\n")], {(package, name)}
    todo = field_types(text, package)
    while todo:
        dep = todo.pop(0)
        if dep in seen:
            continue
        seen.add(dep)
        dep_text = msg_text(*dep, search)
        parts.append(f"{SEPARATOR}\nMSG: {dep[0]}/msg/{dep[1]}\n{dep_text.rstrip(chr(10))}")
        todo[:0] = [d for d in field_types(dep_text, dep[0]) if d not in seen]  # depth first
    return "\n".join(parts) + "\n"
