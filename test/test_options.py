# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""One definition per option: the flags, the node parameters and the documented config are made
from the dataclass fields, and behave as the fields say."""
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import import_ros

from active_recognition.argument_checks import check_mapping, group
from active_recognition.cli import build_parser
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.model import checkpoint
from active_recognition.options import command_options as co
from active_recognition.options.camera_params import SimulatedCameraParameters
from active_recognition.options.flags_and_parameters import leaves, parameters
from active_recognition.options.recognizer_params import RecognizerParameters
from active_recognition.options_docs import flag_rows, generated
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.train import TrainConfig, preset_config

COMMANDS = build_parser()._subparsers._group_actions[0].choices
OPTIONS = {"render": co.RenderOptions, "dataset": co.DatasetOptions, "demo": co.DemoOptions,
           "recognize": co.RecognizeOptions,
           "evaluate": EvalConfig, "train": TrainConfig}


def parse(command, *argv):
    return COMMANDS[command].parse_args([str(a) for a in argv])


def test_the_generated_docs_and_node_yaml_are_up_to_date():
    """docs/options.md and config/{recognizer,simulated_camera}.yaml are generated from the option
    fields. This fails when someone edits a field (its default, help or range) without running
    `python -m active_recognition.options_docs --write`, or edits a generated file by hand."""
    for path, text in generated().items():
        assert path.read_text(encoding="utf-8") == text, f"{path} is out of date: regenerate it"


@pytest.mark.parametrize("command", ["render", "dataset", "demo", "evaluate"])
def test_a_flag_left_out_is_the_dataclass_default(command):
    args = parse(command, *(["--mesh", "m.obj"] if command == "render" else []))
    cls = OPTIONS[command]
    for leaf in leaves(cls):
        if leaf.meta("flag") is not False and leaf.name != "mesh":
            assert getattr(args, leaf.name) == leaf.default, leaf.name
    if command == "evaluate":
        assert EvalConfig(**group(EvalConfig, vars(args))) == EvalConfig()


def test_train_flags_left_out_are_the_preset_or_the_defaults(tmp_path):
    assert preset_config(None, vars(parse("train"))) == TrainConfig()
    (tmp_path / "p.yaml").write_text("min_elevation: 10.0\nsteps: 4\nmodel: {hidden_size: 32, radius: 2}\n")
    cfg = preset_config(tmp_path / "p.yaml", vars(parse("train", "--steps", 3, "--radius", 1.5)))
    assert cfg.steps == 3 and cfg.limits == ViewLimits(10.0, 90.0)  # the flag beats the preset
    assert cfg.model.hidden_size == 32 and cfg.model.radius == 1.5  # the model's keys merge


def test_the_flags_are_spelled_as_the_options_are_named():
    cfg = preset_config(None, vars(parse(
        "train", "--min-elevation", 0, "--max-elevation", 80, "--lr-pretrain", 0.01, "--view-input",
        "--yaw", "--yaw-range", 90, "--hidden-size", 16, "--initial-step", 0.1, -0.2,
        "--policy", "imitation", "--candidates", 50, "--readout", "mean", "--resume", "--stage", "all")))
    assert cfg.limits == ViewLimits(0.0, 80.0) and cfg.lr_pretrain == 0.01 and cfg.yaw and cfg.resume
    assert cfg.yaw_range == 90.0 and cfg.initial_step == [0.1, -0.2]
    assert (cfg.model.view_input, cfg.model.hidden_size, cfg.model.candidates, cfg.model.readout) == (
        True, 16, 50, "mean")
    args = parse("evaluate", "--no-size", "--no-shared", "--yaw", 30, "--planners", "random,straight",
                 "--min-elevation", 0, "--planner-checkpoint", "learned=a.pt")
    cfg = EvalConfig(**group(EvalConfig, vars(args)))
    assert not cfg.size and not cfg.shared and cfg.yaw == 30.0 and cfg.planners == ("random", "straight")
    assert cfg.limits.min_elevation == 0.0 and args.planner_checkpoint == ["learned=a.pt"]
    assert parse("dataset", "--no-cache").no_cache and parse("demo", "--record", "x.mcap").record == "x.mcap"


def numbers():
    for command, parser in COMMANDS.items():
        for action in parser._actions:
            check = getattr(action.type, "check", None)
            if check is not None and check.kind in (int, float) and check.hi is not None:
                yield command, action.option_strings[0], check


@pytest.mark.parametrize("command,flag,check", list(numbers()), ids=lambda v: str(v)[:30])
def test_a_number_past_its_bound_is_refused_in_the_check_s_words(command, flag, check, capsys):
    argv = (["--mesh", "m.obj"] if command == "render" else []) + [flag, str(check.hi + 1)]
    with pytest.raises(SystemExit) as e:
        COMMANDS[command].parse_args(argv)
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"argument {flag}: must be {replace(check, optional=False).allowed()}, got '{check.hi + 1}'" in err, err


@pytest.mark.parametrize("argv,message", [
    (["--stage", "late"], "argument --stage: invalid choice: 'late' (choose from 'pretrain', 'joint', 'loc'"),
    (["--encoder", "resnet"], "argument --encoder: invalid choice: 'resnet' (choose from 'compact', 'wide'"),
    (["--lr-schedule", "step"], "argument --lr-schedule: invalid choice: 'step' (choose from 'constant'"),
    (["--view-gradient", "x"], "argument --view-gradient: invalid choice: 'x' (choose from 'paper', 'surface')"),
])
def test_choices_are_the_module_constants(argv, message, capsys):
    with pytest.raises(SystemExit):
        COMMANDS["train"].parse_args(argv)
    assert message in capsys.readouterr().err


def test_presets_and_the_shipped_checkpoints_configs_load_and_round_trip():
    root = Path(__file__).resolve().parents[1]
    configs = [check_mapping(TrainConfig, checkpoint.read(p)["config"])
               for p in sorted((root / "active_recognition" / "checkpoints").glob("*.pt"))]
    assert len(configs) >= 3
    for values in configs:
        cfg = TrainConfig(**values)
        assert TrainConfig(**check_mapping(TrainConfig, cfg.to_dict())) == cfg
        assert "min_elevation" in cfg.to_dict() and "num_classes" not in cfg.to_dict()["model"]


@pytest.mark.parametrize("cls,node", [(RecognizerParameters, "recognizer"),
                                      (SimulatedCameraParameters, "simulated_camera")])
def test_the_node_declares_each_parameter_with_its_description_range_and_read_only(cls, node):
    import_ros("rclpy")
    import rclpy
    from rclpy.context import Context

    from active_recognition.nodes.recognizer import Recognizer
    from active_recognition.nodes.simulated_camera import SimulatedCameraNode

    expected = parameters(cls)
    assert any(p.bounds for p in expected.values()) and any(not p.read_only for p in expected.values())
    ctx = Context()
    rclpy.init(context=ctx)
    try:
        n = (Recognizer if node == "recognizer" else SimulatedCameraNode)(context=ctx)
        try:
            for d in n.describe_parameters(list(expected)):
                p = expected[d.name]
                assert (d.description, d.read_only) == (p.description, p.read_only), d.name
                assert n.get_parameter(d.name).value == p.default, d.name
                ranges = [(r.from_value, r.to_value, r.step) for r in
                          (*d.floating_point_range, *d.integer_range)]
                assert ranges == ([(*p.bounds, 0)] if p.bounds else []), d.name
        finally:
            n.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)


def test_every_flag_with_choices_shows_the_choices_its_command_accepts():
    """A command that narrows a shared option's choices (open-set-fit's --dataset) says so in
    docs/options.md, and its help with them."""
    for name, parser in COMMANDS.items():
        rows = {row[0]: row for row in flag_rows(parser)}
        for action in parser._actions:
            if action.choices is not None and action.option_strings:
                row = rows[", ".join(action.option_strings)]
                shown = row[2].removeprefix("one of ").removesuffix(", or null").split(", ")
                assert shown == [str(c) for c in action.choices], (name, row)
    fit = {row[0]: row for row in flag_rows(COMMANDS["open-set-fit"])}
    assert fit["--dataset"][1:] == ("modelnet", "one of procedural, modelnet", "the known objects' dataset")
