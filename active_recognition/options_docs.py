# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The documented options, generated from their definitions: docs/options.md (every subcommand's
flags, every node parameter) and config/recognizer.yaml, config/simulated_camera.yaml (each
parameter's default, with its description and range as the comment).

    python -m active_recognition.options_docs --write   # after changing an option
    python -m active_recognition.options_docs --check   # exit 1 when a file is out of date
"""
from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from active_recognition.options.camera_params import SimulatedCameraParameters
from active_recognition.options.flags_and_parameters import parameters, shown
from active_recognition.options.recognizer_params import RecognizerParameters

ROOT = Path(__file__).resolve().parents[1]
WIDTH = 100
NODES = {
    "recognizer": (RecognizerParameters, [
        "# ros2 run active_recognition recognizer --ros-args --params-file config/recognizer.yaml"]),
    "simulated_camera": (SimulatedCameraParameters, [
        "# ros2 run active_recognition simulated_camera --ros-args --params-file "
        "config/simulated_camera.yaml",
        "# The sensor defaults are the model's own virtual camera; `active-recognition demo --camera",
        '# realsense` uses simulated_camera.PRESETS["realsense"] instead (values in the comments).']),
}
GENERATED = "# Generated from the option definitions (python -m active_recognition.options_docs --write)."


def yaml_value(value):
    if isinstance(value, str):
        return f'"{value}"'
    return shown(value) if isinstance(value, bool) else repr(value)


def node_yaml(node):
    """The node's parameter file: every parameter at its default, described in a comment."""
    cls, header = NODES[node]
    lines = [*header, GENERATED, f"{node}:", "  ros__parameters:"]
    for name, p in parameters(cls).items():
        entry = f"    {name}: {yaml_value(p.default)}"
        text = f"{p.description} [{p.check.allowed()}{'' if p.read_only else '; may change at run time'}]"
        pad = max(len(entry) + 2, 32)
        comment = textwrap.wrap(text, WIDTH - pad - 2) or [""]
        lines.append(f"{entry.ljust(pad)}# {comment[0]}")
        lines += [f"{'':{pad}}# {more}" for more in comment[1:]]
    return "\n".join(lines) + "\n"


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def flag_rows(parser):
    """(flag, default, allowed, help) of each flag of a subcommand's parser."""
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        leaf = getattr(action, "option", None)
        flag = ", ".join(action.option_strings) + (
            " " + " ".join(action.metavar) if isinstance(action.metavar, tuple) else "")
        value = leaf.default if leaf is not None else action.default
        default = "required" if action.required else "" if value in (None, []) else shown(value)
        check = leaf.check if leaf is not None else getattr(action.type, "check", None)
        allowed = "" if check is None or check.kind is bool else check.allowed()
        changed = getattr(action, "changed", {})  # a tool's own choices or help (add_flags)
        if "choices" in changed or check is None and action.choices:  # narrowed, or a plain flag's
            allowed = "one of " + ", ".join(map(str, action.choices))
        text = changed.get("help") or (leaf.meta("help", "") if leaf is not None else action.help or "")
        text = text.replace("%%", "%")
        yield flag, default if leaf is None or leaf.check.kind is not bool else "", allowed, text


def options_md():
    """docs/options.md: the command-line flags of every subcommand, then every node parameter."""
    from active_recognition.cli import build_parser

    out = ["# Options", "", "Generated from the option definitions (the dataclass fields made with "
           "`argument_checks.option`): edit a field, then run `python -m active_recognition.options_docs "
           "--write`. A `train` flag left out takes the `--config` preset's value, else the "
           "default shown; a preset's keys are the flags' names with underscores (the model's "
           "under `model:`).", ""]
    commands = build_parser()._subparsers._group_actions[0].choices
    for name, parser in commands.items():
        out += [f"## active-recognition {name}", "", "| flag | default | allowed | what it does |",
                "|---|---|---|---|"]
        out += ["| " + " | ".join(cell(c) for c in row) + " |" for row in flag_rows(parser)]
        out.append("")
    for node, (cls, _) in NODES.items():
        out += [f"## node {node}", "", f"Parameters, in `config/{node}.yaml`. Read-only ones are "
                "read once, at start; the range is the parameter descriptor's.", "",
                "| parameter | default | allowed | read-only | what it does |", "|---|---|---|---|---|"]
        out += [f"| {n} | {cell(yaml_value(p.default))} | {cell(p.check.allowed())} | "
                f"{'yes' if p.read_only else 'no'} | {cell(p.description)} |"
                for n, p in parameters(cls).items()]
        out.append("")
    return "\n".join(out)


def generated():
    """{path: the text it should hold}."""
    files = {ROOT / "docs" / "options.md": options_md()}
    files.update({ROOT / "config" / f"{node}.yaml": node_yaml(node) for node in NODES})
    return files


def write_all(check=False):
    """The generated files that differ from what they should hold (written unless `check`)."""
    stale = []
    for path, text in generated().items():
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            stale.append(path)
            if not check:
                path.write_text(text, encoding="utf-8")
    return stale


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv not in (["--write"], ["--check"]):
        print("usage: python -m active_recognition.options_docs --write | --check", file=sys.stderr)
        return 2
    stale = write_all(check=argv == ["--check"])
    for path in stale:
        print(f"{path.relative_to(ROOT)}: {'out of date' if argv == ['--check'] else 'written'}")
    return 1 if stale and argv == ["--check"] else 0


if __name__ == "__main__":
    sys.exit(main())
