# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Interfaces generated from the option dataclasses: command-line flags and node parameters.

Every option is one dataclass field made with `validation.option` (default, check, help) or
`validation.nested` (a dataclass of options). `add_flags` gives an argparse parser a flag per
option (the field's name with dashes; a boolean that defaults to true is `--no-NAME`), typed by
the field's check, so a bad value is refused with the check's words. `parameters` lists a node's
parameters with what a ROS descriptor says of them (nodes/__init__.py declares them).
options_docs.py writes docs/options.md and the nodes' config/*.yaml from the same definitions.
"""
from __future__ import annotations

import argparse
import dataclasses
from dataclasses import dataclass

from active_recognition.argument_checks import Check, InputError, arg


@dataclass(frozen=True)
class Leaf:
    name: str
    field: dataclasses.Field
    default: object
    runtime: bool

    @property
    def check(self) -> Check:
        return self.field.metadata["check"]

    def meta(self, key, default=None):
        return self.field.metadata.get(key, default)


def leaves(cls, instance=None, runtime=False):
    """Every option of dataclass `cls`, nested ones flattened, with its default as `instance`
    (default: cls()) holds it: a nested field's default may differ from its class's."""
    instance = cls() if instance is None else instance
    out = []
    for f in dataclasses.fields(cls):
        value = getattr(instance, f.name)
        if "nested" in f.metadata:
            out += leaves(f.metadata["nested"], value, runtime or f.metadata["runtime"])
        elif "check" in f.metadata:
            out.append(Leaf(f.name, f, value, runtime or f.metadata.get("runtime", False)))
    names = [leaf.name for leaf in out]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise TypeError(f"{cls.__name__}: options {twice} appear twice among its nested options")
    return out


def shown(value):
    """A default as a user types it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (tuple, list)):
        return ",".join(map(shown, value)) if isinstance(value, tuple) else " ".join(map(shown, value))
    return str(value)


def comma_list(check):
    """An argparse type for `a,b` on the command line: the names, checked as the option checks
    them, so a bad one is refused naming the flag."""
    def parse(text):
        names = tuple(p.strip() for p in text.split(","))
        try:
            for name in names if check.items else ():
                check.items("", name)  # the bad name itself, not the list, is what the error shows
            return check("", names)
        except InputError as e:  # "argument --planners: must be one of ..., got 'psychic'"
            raise argparse.ArgumentTypeError(str(e).strip()) from None
    parse.__name__ = "list"
    return parse


def flag_name(leaf):
    if leaf.meta("flag"):
        return leaf.meta("flag")
    dashed = leaf.name.replace("_", "-")
    return f"--no-{dashed}" if leaf.check.kind is bool and leaf.default else f"--{dashed}"


def flag_kwargs(leaf, unset):
    """argparse keywords of `leaf`'s flag; `unset`: the flag defaults to None (a preset fills in)."""
    check, default = leaf.check, leaf.default
    kw = {"dest": leaf.name, "default": None if unset else default}
    if check.kind is bool:
        kw["action"] = "store_false" if default else "store_true"
    elif check.choices is not None:
        kw["choices"] = check.choices
    elif check.kind is list:
        kw.update(nargs=check.length[0], type=arg(check.items))
    elif check.kind is tuple:
        kw["type"] = comma_list(check)
    else:
        kw["type"] = arg(check)
    if leaf.meta("metavar"):
        kw["metavar"] = leaf.meta("metavar")
    if leaf.meta("required"):
        kw.update(required=True, default=None)
    text = leaf.meta("help", "")
    if check.kind is not bool and default not in (None, "", [], ()) and not leaf.meta("required"):
        text += f" (default {shown(default)})"
    kw["help"] = text.replace("%", "%%")
    return kw


def add_flags(parser, cls, names=None, *, unset=False, **changes):
    """A flag for every option of `cls` that has one (or for those in `names`, in that order),
    each changed by `changes` ({name: argparse keywords}: a tool's own default, choices, help).
    Each action keeps its option as `.option` and the changes as `.changed` (the generated
    reference reads them)."""
    known = {leaf.name: leaf for leaf in leaves(cls)}
    chosen = [known[n] for n in names] if names else [
        leaf for leaf in known.values() if leaf.meta("flag") is not False]
    groups = {}
    for leaf in chosen:
        exclusive = leaf.meta("exclusive")
        if exclusive is not None and exclusive not in groups:
            groups[exclusive] = parser.add_mutually_exclusive_group()
        where = groups.get(exclusive, parser)
        change = changes.get(leaf.name, {})
        if "default" in change:  # a tool's own default, said in the help
            leaf = dataclasses.replace(leaf, default=change["default"])
        action = where.add_argument(flag_name(leaf), **{**flag_kwargs(leaf, unset), **change})
        action.option, action.changed = leaf, change
    return parser


class Parser(argparse.ArgumentParser):
    """argparse, but a bad option is one line (the error and where help is), not the usage."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


@dataclass(frozen=True)
class Param:
    """A node parameter as its ROS descriptor declares it."""

    name: str
    default: object
    check: Check
    description: str
    read_only: bool

    @property
    def bounds(self):
        """(from, to) where the check bounds a number on both sides, else None."""
        c = self.check
        if c.kind in (int, float) and c.lo is not None and c.hi is not None:
            return (c.kind(c.lo), c.kind(c.hi))
        return None


def parameters(cls):
    """{name: Param} of a node whose parameters are the options of dataclass `cls`; those not
    marked runtime are read-only (the node reads them once, at start)."""
    return {leaf.name: Param(leaf.name, leaf.default, leaf.check, leaf.meta("help", ""),
                             not leaf.runtime) for leaf in leaves(cls)}
