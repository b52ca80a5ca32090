# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Shipped configuration files stay in step with the code that reads them."""
import dataclasses
from pathlib import Path

import pytest
import yaml

from active_recognition.model import ModelConfig
from active_recognition.train import TrainConfig

CONFIG = Path(__file__).resolve().parents[1] / "config"


@pytest.mark.parametrize("path", sorted(CONFIG.glob("train_*.yaml")) + sorted(CONFIG.glob("ablation_*.yaml")),
                         ids=lambda p: p.name)
def test_training_presets_are_valid(path):
    values = yaml.safe_load(path.read_text())
    TrainConfig(**values)
    ModelConfig(**values.get("model", {}))


@pytest.mark.parametrize("node", ["recognizer", "simulated_camera"])
def test_node_yaml_documents_every_declared_parameter(node):
    pytest.importorskip("rclpy")
    import importlib
    module = importlib.import_module(f"active_recognition.nodes.{node}")
    values = yaml.safe_load((CONFIG / f"{node}.yaml").read_text())[node]["ros__parameters"]
    assert set(values) == set(module.PARAMS)
    for name, value in values.items():
        assert type(value) is type(module.PARAMS[name][0]), name


def test_train_config_fields_have_cli_flags():
    from active_recognition.cli import build_parser
    train = build_parser()._subparsers._group_actions[0].choices["train"]
    dests = {a.dest for a in train._actions}
    assert {f.name for f in dataclasses.fields(TrainConfig)} - {"model"} <= dests


@pytest.mark.parametrize("bad,match", [({"step_weighting": "late"}, "step weighting"),
                                       ({"initial_step": [0.1]}, "initial step"),
                                       ({"initial_step": [0.1, float("nan")]}, "initial step")])
def test_bad_training_options_are_named(bad, match):
    with pytest.raises(ValueError, match=match):
        TrainConfig(**bad)
