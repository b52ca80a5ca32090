# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0


"""One way to check what a user gives: options, presets, node parameters, command-line numbers.

A dataclass field made with `option(default, ...)` carries a `Check` (type, range, choices,
length, nested options) and its help in its metadata: it is the one definition of that option,
from which options/flags_and_parameters.py makes the flags and node parameters. `nested(cls)` holds a dataclass of
options (flat: its keys beside the outer ones). `validate(obj)` applies every field's check (call
it in __post_init__), `check_mapping(cls, values)` names unknown keys, nested ones too, `group`
and `as_dict` map flat names to nested fields and back, `arg(check)` turns a check into an
argparse type, and `load_yaml` names the file and line of a syntax error.
NaN and infinity are refused wherever a number is read. Every refusal is an `InputError` whose
message names the key, the value and what is allowed.
"""
from __future__ import annotations

import argparse
import dataclasses
import difflib
import math
import re
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import yaml

SEED_MAX = 2 ** 32 - 1
KINDS = {bool: "true or false", int: "an integer", float: "a finite number", str: "a string",
         list: "a list", tuple: "a list", dict: "a mapping"}
PLURALS = {bool: "booleans", int: "integers", float: "finite numbers", str: "strings"}


class InputError(ValueError):
    """Bad input (an option, a preset, a parameter, a file): the message names the thing, the value
    and what is allowed. The CLI prints it as one line and exits with status 2."""


@dataclass(frozen=True)
class Check:
    kind: type                      # bool, int, float, str, list, tuple or dict
    lo: float | None = None         # numbers: the bounds (inclusive unless *_open)
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple | None = None
    optional: bool = False          # None is allowed
    length: tuple | None = None     # (min, max or None): length of a string, list or mapping
    items: Check | None = None      # every element of a list
    schema: type | None = None      # a mapping of this dataclass's options (checked by its fields)
    pattern: str | None = None      # strings: a full match of this regular expression
    text: str | None = None         # what is allowed, in words, where the parts above say it badly

    def allowed(self) -> str:
        if self.text:
            words = self.text
        elif self.choices is not None:
            words = "one of " + ", ".join(map(str, self.choices))
        elif self.schema is not None:
            names = ", ".join(checks(self.schema))
            words = f"a mapping of {self.schema.__name__} options ({names})"
        elif self.kind is str and self.length == (1, None):
            words = "a non-empty string"
        else:
            words = KINDS[self.kind] + self._bounds()
        return words + (", or null" if self.optional else "")

    def _bounds(self):
        if self.length is not None:
            lo, hi = self.length
            if self.kind is str:
                return f" of {lo} to {hi} characters"
            count = f"{lo}" if hi == lo else f"{lo} or more" if hi is None else f"{lo} to {hi}"
            items = self.items
            what = ("names from " + ", ".join(map(str, items.choices)) if items and items.choices
                    else PLURALS[items.kind] if items else "items")
            return f" of {count} {what}"
        if self.lo is not None and self.hi is not None:
            if self.kind is int:
                return f" from {self.lo} to {self.hi}"
            return (f" in {'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}"
                    f"{')' if self.hi_open else ']'}")
        if self.lo is not None:
            return f" {'>' if self.lo_open else '>='} {self.lo:g}"
        if self.hi is not None:
            return f" {'<' if self.hi_open else '<='} {self.hi:g}"
        return ""

    def __call__(self, name, value):
        """`value` normalised (an integer where a number belongs becomes a float), else InputError
        naming `name`."""
        if value is None and self.optional:
            return None
        bad = InputError(f"{name} must be {self.allowed()}, got {value!r}")
        value = self._typed(value, bad)
        if self.kind in (int, float) and not self._in_range(value):
            raise bad
        if self.choices is not None and value not in self.choices:
            raise bad
        if self.pattern is not None and not re.fullmatch(self.pattern, value):
            raise bad
        if self.length is not None and not (
                self.length[0] <= len(value) <= (self.length[1] or math.inf)):
            raise bad
        if self.items is not None:
            value = self.kind(self.items(f"{name}[{i}]", v) for i, v in enumerate(value))
        if self.schema is not None:
            value = check_mapping(self.schema, value, name + ".")
        return value

    def _typed(self, value, bad):
        if self.kind is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise bad
            if not math.isfinite(value):
                raise bad
            return float(value)
        if self.kind is int and isinstance(value, bool):
            raise bad
        if self.kind in (list, tuple) and isinstance(value, (list, tuple)):
            return self.kind(value)
        if self.kind is dict and isinstance(value, Mapping):
            return dict(value)
        if not isinstance(value, self.kind):
            raise bad
        return value

    def _in_range(self, value):
        lo, hi = self.lo, self.hi
        return ((lo is None or (value > lo if self.lo_open else value >= lo))
                and (hi is None or (value < hi if self.hi_open else value <= hi)))


def option(default, kind=None, *, help="", flag=None, metavar=None, runtime=False,  # noqa: A002
           required=False, exclusive=None, **check):
    """A dataclass field with its Check (the kind defaults to the default value's type) and what the
    generated interfaces say of it (options/flags_and_parameters.py): `help`; `flag` the command-line spelling (False:
    none), `metavar`, `required`, `exclusive` (flags of one name exclude each other); `runtime`: a
    node may change it while running (else its parameter is read-only)."""
    meta = {"check": Check(kind or type(default), **check), "help": help, "flag": flag,
            "metavar": metavar, "runtime": runtime, "required": required, "exclusive": exclusive}
    if isinstance(default, (list, dict)):
        return dataclasses.field(default_factory=lambda: type(default)(default), metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def nested(cls, default=None, *, flat=False, runtime=False, help=""):  # noqa: A002
    """A dataclass field holding the options of dataclass `cls` (an instance; a mapping of its
    options is taken too, over `default`). `flat`: its options sit beside the outer ones in YAML,
    in saved configs and among node parameters (ViewLimits' min_elevation), not under the
    field's name (model: {hidden_size: ...}). `runtime` holds for all of its options."""
    meta = {"check": Check(dict, schema=cls), "nested": cls, "flat": flat, "runtime": runtime,
            "help": help}
    return dataclasses.field(default_factory=lambda: dataclasses.replace(default or cls()),
                             metadata=meta)


def checks(cls):
    """{option name: Check} of a dataclass made with `option` fields (a flat nested one's inline)."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.metadata.get("flat"):
            out.update(checks(f.metadata["nested"]))
        elif "check" in f.metadata:
            out[f.name] = f.metadata["check"]
    return out


def validate(obj, prefix=""):
    """Check and normalise every `option` field of a dataclass instance (frozen ones too); a nested
    field given as a mapping becomes its dataclass."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if "nested" in f.metadata:
            value = _instance(f, value, prefix)
        elif "check" in f.metadata:
            value = f.metadata["check"](prefix + f.name, value)
        object.__setattr__(obj, f.name, value)


def _instance(f, value, prefix):
    cls = f.metadata["nested"]
    if isinstance(value, cls):
        return value
    if not isinstance(value, Mapping):
        raise InputError(f"{prefix}{f.name} must be {f.metadata['check'].allowed()}, got {value!r}")
    inner = prefix if f.metadata["flat"] else f"{prefix}{f.name}."
    return dataclasses.replace(f.default_factory(), **check_mapping(cls, value, inner))


def group(cls, values):
    """{option name: value} (every option of `cls` by its own name, nested ones too, as the
    command line and the node parameters name them) as keyword arguments of `cls`: a nested
    field's options as a mapping under its name. Names `cls` does not know are left out."""
    out = {}
    for f in dataclasses.fields(cls):
        if "nested" in f.metadata:
            inner = group(f.metadata["nested"], values)
            if inner:
                out[f.name] = inner
        elif f.name in values:
            out[f.name] = values[f.name]
    return out


def as_dict(obj):
    """A dataclass instance as the mapping a YAML preset holds: flat nested options inline."""
    out = {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.metadata.get("flat"):
            out.update(as_dict(value))
        else:
            out[f.name] = as_dict(value) if "nested" in f.metadata else value
    return out


def check_mapping(cls, values, prefix=""):
    """`values` checked as options of dataclass `cls`: unknown keys are named, with a guess. The
    options of a flat nested field come back as a mapping under its name."""
    if not isinstance(values, Mapping):
        raise InputError(f"{prefix.rstrip('.') or 'the options'} must be a mapping of "
                         f"{cls.__name__} options, got {values!r}")
    known = checks(cls)
    for key in values:
        if key not in known:
            guess = difflib.get_close_matches(str(key), known, 1)
            raise InputError(f"unknown option {prefix}{key}" + (
                f" (did you mean {prefix}{guess[0]}?)" if guess else
                f" (known: {', '.join(known)})"))
    checked = {key: known[key](prefix + key, value) for key, value in values.items()}
    own = {f.name: f for f in dataclasses.fields(cls)}
    return {**{k: v for k, v in checked.items() if k in own},
            **{k: v for k, v in group(cls, checked).items() if own[k].metadata.get("flat")}}


def arg(check):
    """An argparse type function that parses a command-line word and applies `check`."""
    def parse(text):
        try:
            value = check.kind(text) if check.kind in (int, float) else text
            return check("", value)
        except ValueError:  # int("x"), float("x") and InputError alike
            words = dataclasses.replace(check, optional=False).allowed()  # no null on a command line
            raise argparse.ArgumentTypeError(f"must be {words}, got {text!r}") from None
    parse.__name__ = check.kind.__name__  # argparse names the type in some messages
    parse.check = check  # for the generated reference (options/flags_and_parameters.py)
    return parse


class _Loader(yaml.SafeLoader):
    """SafeLoader that reads 1e-3 as a number (as YAML 1.2 does) and refuses duplicate keys."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if not isinstance(key, (str, int, float, bool, type(None))):
                raise yaml.constructor.ConstructorError(None, None, f"a key must be a name, not "
                                                        f"{key!r}", key_node.start_mark)
            if key in seen:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}",
                                                        key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep)


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(
    r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789"))


def load_yaml(path, what="config"):
    """The mapping a YAML file holds ({} when empty); InputError naming the file (and the line of
    a syntax error) for anything else."""
    text = read_text(path, what)
    try:
        values = yaml.load(text, Loader=_Loader)
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise InputError(f"{what} {path}{where}: {e.problem or e.context}") from None
    except yaml.YAMLError as e:
        raise InputError(f"{what} {path}: not valid YAML ({e})") from None
    if values is None:
        return {}
    if not isinstance(values, dict):
        raise InputError(f"{what} {path}: must hold a mapping of options, not a "
                         f"{type(values).__name__}")
    return values


def read_text(path, what="file"):
    """A text file's contents; InputError naming it when it is missing, a folder or not text."""
    path = input_file(path, what)
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{what} {path}: not a text file (not UTF-8)") from None
    except OSError as e:
        raise InputError(f"{what} {path}: cannot be read ({e.strerror or e})") from None


def input_file(path, what="file"):
    """Path of an existing, readable file; InputError otherwise."""
    if str(path) == "":
        raise InputError(f"{what}: empty path")
    path = Path(path)
    if not path.exists():
        raise InputError(f"{what} {path}: no such file")
    if not path.is_file():
        raise InputError(f"{what} {path}: is a directory, not a file")
    try:
        path.open("rb").close()
    except OSError as e:
        raise InputError(f"{what} {path}: cannot be read ({e.strerror or e})") from None
    return path


def output_dir(path, what="output folder"):
    """Create folder `path` if needed and make sure a file can be written in it; InputError
    naming it otherwise. Called before any work starts."""
    if str(path) == "":
        raise InputError(f"{what}: empty path")
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{what} {path}: exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError as e:
        raise InputError(f"{what} {path}: cannot write there ({e.strerror or e})") from None
    return path


def output_file(path, what="output file", suffix=None):
    """A file path that can be written: not a directory, in a folder that can be written, with
    `suffix` (e.g. ".png") if given."""
    if str(path) == "" or Path(path).name in ("", ".", ".."):
        raise InputError(f"{what} {str(path)!r}: not a file name")
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{what} {path}: is a directory; name a file")
    if suffix and path.suffix.lower() != suffix:
        raise InputError(f"{what} {path}: must end in {suffix}")
    output_dir(path.parent, f"{what} {path}: its folder")
    if path.exists() and not path.is_file():
        raise InputError(f"{what} {path}: exists and is not a regular file")
    return path
