# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Configuration: shipped files stay in step with the code, and every bad value is named."""
import argparse
import dataclasses
import math
from pathlib import Path

import pytest

from active_recognition.argument_checks import Check, InputError, arg, check_mapping, checks, load_yaml
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.model.episode import EpisodeConfig
from active_recognition.model.network import ModelConfig
from active_recognition.options.camera_params import CameraNodeConfig, ObjectSource
from active_recognition.options.recognizer_params import NodeConfig
from active_recognition.runtime.active_recognizer import SensingConfig
from active_recognition.sensing.reach import ViewLimits
from active_recognition.simulation.depth_sensor import SensorConfig
from active_recognition.training.train import TrainConfig

CONFIG = Path(__file__).resolve().parents[1] / "config"
CONFIGS = [TrainConfig, EvalConfig, ModelConfig, EpisodeConfig, SensingConfig, SensorConfig, ViewLimits,
           NodeConfig, ObjectSource, CameraNodeConfig]


@pytest.mark.parametrize("path", sorted(CONFIG.glob("train_*.yaml")) + sorted(CONFIG.glob("ablation_*.yaml")),
                         ids=lambda p: p.name)
def test_training_presets_are_valid(path):
    values = check_mapping(TrainConfig, load_yaml(path))  # no unknown keys, nested ones too
    TrainConfig(**values)
    ModelConfig(**values.get("model", {}))


@pytest.mark.parametrize("cls", CONFIGS, ids=lambda c: c.__name__)
def test_every_option_has_a_check_and_the_defaults_pass_it(cls):
    flat = {f.name for f in dataclasses.fields(cls) if f.metadata.get("flat")}
    inline = {n for f in dataclasses.fields(cls) if f.name in flat for n in checks(f.metadata["nested"])}
    assert {f.name for f in dataclasses.fields(cls)} - flat | inline == set(checks(cls))
    cls()  # the defaults are allowed values


NUMBERS = [(cls, name) for cls in CONFIGS for name, check in checks(cls).items()
           if check.kind in (int, float) and name in {f.name for f in dataclasses.fields(cls)}]


@pytest.mark.parametrize("cls,name", NUMBERS, ids=[f"{c.__name__}.{n}" for c, n in NUMBERS])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, "1", True, None])
def test_every_number_refuses_nan_inf_strings_and_booleans(cls, name, bad):
    with pytest.raises(InputError) as e:
        cls(**{name: bad})
    assert name in str(e.value) and f"got {bad!r}" in str(e.value)


@pytest.mark.parametrize("values,message", [
    ({"lr_pretrain": math.nan}, "lr_pretrain must be a finite number > 0, got nan"),
    ({"lr_joint": -1}, "lr_joint must be a finite number > 0, got -1"),
    ({"pretrain_epochs": -1}, "pretrain_epochs must be an integer from 0 to 100000, got -1"),
    ({"pretrain_epochs": 2.5}, "pretrain_epochs must be an integer from 0 to 100000, got 2.5"),
    ({"pretrain_epochs": "many"}, "pretrain_epochs must be an integer"),
    ({"checkpoint_every": 0}, "checkpoint_every must be an integer >= 1, got 0"),
    ({"device": "tpu9"}, "device must be cpu, cuda or cuda:N, got 'tpu9'"),
    ({"step_weighting": "late"}, "step_weighting must be one of uniform, early, got 'late'"),
    ({"initial_step": [0.1]}, "initial_step must be a list of 2 finite numbers, or null"),
    ({"initial_step": [0.1, math.nan]}, r"initial_step\[1\] must be a finite number, got nan"),
    ({"initial_step": [0.0, 0.9]}, "initial step .* must lie inside the increment bound"),
    ({"model": 5}, r"model must be a mapping of ModelConfig options \(num_classes, encoder"),
    ({"model": {"hiden_size": 12}}, r"unknown option model.hiden_size \(did you mean "
                                    r"model.hidden_size\?\)"),
    ({"model": {"hidden_size": 0}}, "model.hidden_size must be an integer from 1 to 8192, got 0"),
    ({"model": {"max_step": -1}}, r"model.max_step must be a finite number in \(0, 3.14159\]"),
    ({"model": {"num_classes": 3}}, "model.num_classes comes from the dataset"),
    ({"policy": "imitation"}, "policy imitation needs a view-scoring head"),
    ({"pretrain_epochs": 0, "joint_epochs": 0}, "nothing to train"),
    ({"stage": "joint", "joint_epochs": 0}, "nothing to train"),
    ({"stage": "loc", "loc_epochs": 2}, "stage loc fits FC_loc of a trained model: run it with --resume"),
    ({"model": {"loc_hidden": 8}}, "model.loc_hidden is FC_loc's hidden layer, which stage loc trains"),
    ({"root": ""}, "root must be a non-empty string, or null, got ''"),
])
def test_bad_training_options_are_named(values, message):
    with pytest.raises(InputError, match=message):
        TrainConfig(**values)


@pytest.mark.parametrize("cls,values,message", [
    (EvalConfig, {"starts": 0}, "starts must be an integer from 1 to 50, got 0"),
    (EvalConfig, {"objects": -1}, "objects must be an integer >= 0, got -1"),
    (EvalConfig, {"planners": ("psychic",)}, r"planners\[0\] must be one of learned, random"),
    (EvalConfig, {"planners": ()}, "planners must be a list of 1 or more"),
    (EvalConfig, {"planners": ("random", "random")}, "random named more than once"),
    (EvalConfig, {"split": "dev"}, "split must be one of train, val, test, cross, got 'dev'"),
    (EpisodeConfig, {"max_views": 0}, "max_views must be an integer from 1 to 1000, got 0"),
    (SensingConfig, {"box_margin": 2}, r"box_margin must be a finite number in \[0, 1\], got 2"),
    (SensorConfig, {"noise": "pink"}, "camera noise must be one of none, kinect, got 'pink'"),
    (SensorConfig, {"width": 0}, "camera width must be an integer from 1 to 4096, got 0"),
    (SensorConfig, {"min_range": 2.0, "max_range": 1.0}, "max_range .* more than min_range"),
])
def test_bad_options_of_the_other_configs_are_named(cls, values, message):
    with pytest.raises(InputError, match=message):
        cls(**values)


def test_an_integer_where_a_number_belongs_is_a_number():
    cfg = TrainConfig(lr_joint=1, model={"radius": 2})
    assert cfg.lr_joint == 1.0 and type(cfg.lr_joint) is float
    assert cfg.model.radius == 2.0 and type(cfg.model.radius) is float


@pytest.mark.parametrize("text,message", [
    ("pretrain_epochs: 1\n  joint_epochs: [\n", "bad.yaml, line 2, column 15: mapping values"),
    ("seed: 1\nseed: 2\n", "bad.yaml, line 2, column 1: duplicate key 'seed'"),
    ("- 1\n- 2\n", "bad.yaml: must hold a mapping of options, not a list"),
    ("model: {hidden_size: [1\n", "bad.yaml, line 2"),
    ("[1, 2]: x\n", r"bad.yaml, line 1, column 1: a key must be a name, not \[1, 2\]"),
    ("\t seed: 1\n", "bad.yaml, line 1, column 1: found character .* that cannot start any token"),
])
def test_yaml_errors_name_the_file_and_the_line(tmp_path, text, message):
    (tmp_path / "bad.yaml").write_text(text)
    with pytest.raises(InputError, match=message):
        load_yaml(tmp_path / "bad.yaml")


def test_yaml_reads_exponents_as_numbers_and_empty_files_as_nothing(tmp_path):
    (tmp_path / "a.yaml").write_text("lr_pretrain: 1e-3\nlr_joint: 2.5E+1\nout: 1e3x\n")
    assert load_yaml(tmp_path / "a.yaml") == {"lr_pretrain": 0.001, "lr_joint": 25.0, "out": "1e3x"}
    (tmp_path / "empty.yaml").write_text("# nothing but a comment\n")
    assert load_yaml(tmp_path / "empty.yaml") == {}


def test_a_yaml_path_that_is_no_text_file_is_named(tmp_path):
    with pytest.raises(InputError, match="nope.yaml: no such file"):
        load_yaml(tmp_path / "nope.yaml")
    with pytest.raises(InputError, match="is a directory, not a file"):
        load_yaml(tmp_path)
    (tmp_path / "bin.yaml").write_bytes(bytes(range(256)))
    with pytest.raises(InputError, match="bin.yaml: not a text file"):
        load_yaml(tmp_path / "bin.yaml")


def test_command_line_numbers_are_checked_by_the_same_rule():
    parse = arg(Check(int, lo=1, hi=50))
    assert parse("7") == 7
    for text in ("0", "51", "x", "1.5", "nan"):
        message = f"must be an integer from 1 to 50, got '{text}'"
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)
    with pytest.raises(argparse.ArgumentTypeError, match="got 'inf'"):
        arg(Check(float))("inf")
