# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The package's layers, as rules: each layer imports only from the layers below it, and what the
recognizer node imports loads nothing of the harness (training, evaluation, benchmarks) or of the
dataset generators and the simulated camera. The README's Layout lists the same folders. The
node's state is its own: its outputs and action server read none of it, and no one writes the
controller's or the core's fields but themselves."""
import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from test_house import import_graph

ROOT = Path(__file__).resolve().parents[1]
PKG = "active_recognition"

# Bottom to top, in the order the data flows. A module may import its own layer and those before
# it. The top-level argument_checks and atomic_files are the foundation every layer may use; cli
# and the docs generator (options_docs, which reads cli's parsers) are the top.
LAYERS = ("foundation", "sensing", "unknown", "model", "runtime", "datasets", "simulation", "options",
          "training", "evaluation", "nodes", "commands")
TOP_LEVEL = {"argument_checks": "foundation", "atomic_files": "foundation", "cli": "commands",
             "options_docs": "commands", "__init__": "foundation"}
# unknown/fit.py fits the unknown answer by running episodes (evaluate, the simulated camera): it
# lives with the rest of the unknown answer but is harness code, so it counts as evaluation.
EXCEPTIONS = {f"{PKG}.unknown.fit": "evaluation"}
# What the recognizer node must never load: the harness and the generators of objects.
FORBIDDEN = (f"{PKG}.training", f"{PKG}.evaluation", f"{PKG}.datasets", f"{PKG}.simulation",
             f"{PKG}.unknown.fit", f"{PKG}.options.camera_params", f"{PKG}.options.command_options",
             f"{PKG}.nodes.demo", f"{PKG}.nodes.simulated_camera", "benchmarks")


def layer_of(module):
    """The layer of a dotted module name of the package."""
    if module in EXCEPTIONS:
        return EXCEPTIONS[module]
    parts = module.split(".")
    if len(parts) == 1:
        return "foundation"
    return TOP_LEVEL[parts[1]] if len(parts) == 2 and parts[1] in TOP_LEVEL else parts[1]


def test_every_folder_and_top_level_module_has_a_layer():
    package = ROOT / PKG
    folders = {p.name for p in package.iterdir() if (p / "__init__.py").is_file()}
    modules = {p.stem for p in package.glob("*.py")}
    assert folders <= set(LAYERS), f"a folder of no declared layer: {sorted(folders - set(LAYERS))}"
    assert modules <= set(TOP_LEVEL), f"a top-level module of no declared layer: {sorted(modules - set(TOP_LEVEL))}"
    assert len(modules - {"__init__"}) <= 8, "the top level keeps at most 8 modules: give new ones a layer's folder"


def test_each_layer_imports_only_from_the_layers_below():
    graph = import_graph(ROOT, (PKG,))
    rank = {name: i for i, name in enumerate(LAYERS)}
    upward = sorted(f"{a} ({layer_of(a)}) imports {b} ({layer_of(b)})"
                    for a, targets in graph.items() for b in targets
                    if rank[layer_of(b)] > rank[layer_of(a)])
    assert upward == [], "\n".join(upward)


def test_the_layer_rule_sees_an_upward_import():
    assert layer_of(f"{PKG}.runtime.controller") == "runtime"
    assert layer_of(f"{PKG}.argument_checks") == "foundation" and layer_of(f"{PKG}.cli") == "commands"
    assert layer_of(f"{PKG}.unknown.fit") == "evaluation" and layer_of(f"{PKG}.unknown.scores") == "unknown"
    graph = import_graph(ROOT, (PKG,))
    assert f"{PKG}.sensing.geometry" in graph[f"{PKG}.model.episode"]  # the graph sees absolute imports


def loaded_by(module):
    """The modules a fresh interpreter holds after importing `module` (no test's imports in it)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    code = f"import json, sys, {module}; print(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_recognizer_node_loads_no_harness_no_dataset_and_no_simulated_camera():
    """A robot runs the recognizer node: its imports, all of them, load nothing of training,
    evaluation, benchmarks, the datasets (their generators) or the simulated camera; declaring its
    parameters (options.recognizer_params) needs none of them."""
    pytest.importorskip("rclpy")
    loaded = loaded_by(f"{PKG}.nodes.recognizer")
    assert f"{PKG}.runtime.active_recognizer" in loaded and f"{PKG}.options.recognizer_params" in loaded
    found = [m for m in loaded if m.startswith(FORBIDDEN)]
    assert found == []


def test_no_two_modules_share_a_file_name():
    """A name says which module: no two files of the package and msg_adapters share one (the core
    recognizer is runtime/active_recognizer.py beside nodes/recognizer.py), nor a benchmark one of
    theirs (benchmarks/depth_layer_speed.py, not a second depth_layer.py)."""
    names = {}
    for folder in (PKG, "msg_adapters"):
        for path in (ROOT / folder).rglob("*.py"):
            if path.name != "__init__.py":
                names.setdefault(path.name, []).append(str(path.relative_to(ROOT)))
    shared = {name: paths for name, paths in names.items() if len(paths) > 1}
    assert shared == {}
    clash = sorted(p.name for p in (ROOT / "benchmarks").glob("*.py") if p.name in names)
    assert clash == []


# What the recognizer's outputs and action server may use of the node: rclpy's factories and clock.
RCLPY = {"create_lifecycle_publisher", "destroy_lifecycle_publisher", "create_guard_condition", "get_clock"}


def node_reads(source):
    """The attributes a module reads off `node` or `self.node`."""
    return {n.attr for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Attribute) and (
        isinstance(n.value, ast.Name) and n.value.id == "node" or isinstance(n.value, ast.Attribute)
        and n.value.attr == "node" and isinstance(n.value.value, ast.Name) and n.value.value.id == "self")}


def written_fields(source, owners):
    """`a.b` fields assigned in a module (`a`, `self.a`, `x.y.a`), for each `a` in `owners`."""
    out = set()
    for n in ast.walk(ast.parse(source)):
        targets = n.targets if isinstance(n, ast.Assign) else [n.target] if isinstance(n, ast.AugAssign) else []
        for t in (e for t in targets for e in (t.elts if isinstance(t, ast.Tuple) else [t])):
            t = t.value if isinstance(t, ast.Starred) else t
            if isinstance(t, ast.Attribute):
                base = t.value.attr if isinstance(t.value, ast.Attribute) else getattr(t.value, "id", None)
                if base in owners:
                    out.add(f"{base}.{t.attr}")
    return out


def test_the_outputs_and_the_action_server_read_no_state_of_the_node():
    for name in ("recognizer_outputs.py", "recognize_server.py"):
        assert node_reads((ROOT / PKG / "nodes" / name).read_text()) <= RCLPY, name


def test_only_the_controller_and_the_core_write_their_fields():
    for path in sorted((ROOT / PKG / "nodes").glob("*.py")):
        assert written_fields(path.read_text(), {"loop", "core", "controller"}) == set(), path.name
    assert written_fields((ROOT / PKG / "runtime" / "controller.py").read_text(), {"core", "episode"}) == set()


def test_the_state_rules_see_a_read_and_a_write():
    assert node_reads("def f(node):\n    return node.loop.health, self.node.step_ms\n") == {"loop", "step_ms"}
    assert written_fields("self.loop.require_pose, x = True, 1\nloop.timing += 1\nself.core.episode.config = 2\n",
                          {"loop", "episode"}) == {"loop.require_pose", "loop.timing", "episode.config"}
