# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0


"""The active-recognition command: each subcommand's normal path, and bad input ending in one clear
message (exit status 2, the problem named, no traceback). Tiny datasets and models: seconds."""
import json
import os
import subprocess
import sys
import warnings

import matplotlib.image
import numpy as np
import pytest
import torch
import trimesh
from conftest import import_ros

from active_recognition import cli
from active_recognition.cli import main
from active_recognition.model import checkpoint
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.sensing.meshes import load_mesh

TINY_TRAIN = ["--dataset", "folder", "--pretrain-epochs", "1", "--joint-epochs", "1",
              "--batch-size", "4", "--steps", "2", "--views-per-shape", "2", "--eval-shapes", "2",
              "--checkpoint-every", "2", "--hidden-size", "8", "--seed", "1", "--max-shapes", "8"]


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    """One dataset cache for the module (generated datasets are built once)."""
    old = os.environ.get("ACTIVE_RECOGNITION_CACHE")
    os.environ["ACTIVE_RECOGNITION_CACHE"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if old is None:
        del os.environ["ACTIVE_RECOGNITION_CACHE"]
    else:
        os.environ["ACTIVE_RECOGNITION_CACHE"] = old


@pytest.fixture(scope="module")
def files(tmp_path_factory, tiny_tree):
    """Inputs good and bad, shared by the cases below."""
    d = tmp_path_factory.mktemp("files")
    trimesh.creation.box(extents=(1, 0.5, 0.25)).export(d / "box.stl")
    noise = np.random.default_rng(3).integers(0, 256, 999, np.uint8)
    (d / "noise.obj").write_bytes(noise.tobytes())
    (d / "lie.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1000\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    (d / "a_file").write_text("not a folder")
    (d / "empty.pt").write_bytes(b"")
    (d / "truncated.pt").write_bytes(checkpoint.shipped("procedural").read_bytes()[:5000])
    (d / "one" / "a").mkdir(parents=True)
    trimesh.creation.box().export(d / "one" / "a" / "box.stl")
    (d / "a_dir").mkdir()
    (d / "syntax.yaml").write_text("pretrain_epochs: 1\n  joint_epochs: [\n")
    (d / "nested.yaml").write_text("model: {hiden_size: 12}\n")
    (d / "words.yaml").write_text("pretrain_epochs: many\n")
    (d / "model5.yaml").write_text("model: 5\n")
    (d / "preset.yaml").write_text("joint_epochs: 7\nsteps: 2\nlr_joint: 1e-3\n")
    model = RecurrentAttention(ModelConfig(num_classes=2, hidden_size=8, feature_size=8))
    state = model.state_dict()
    state["classify.weight"] = torch.full_like(state["classify.weight"], float("nan"))
    checkpoint.save(d / "nan.pt", {"model": state, "model_args": model.config.to_dict(),
                                   "classes": ["box", "cylinder"]})
    for c, splits in (("chair", ("train", "test")), ("lamp", ("test",))):
        for split in splits:
            (d / "mn" / c / split).mkdir(parents=True)
            trimesh.creation.box(extents=(1, 0.3 + 0.1 * len(split), 0.4)).export(
                d / "mn" / c / split / f"{c}.off")
    return d


def run(argv, capsys):
    """(exit status, stdout, stderr) of main(argv), as the shell would see them."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as e:  # argparse
        status = e.code
    out, err = capsys.readouterr()
    return status, out, err


def run_process(argv):
    """(exit status, stdout, stderr) of the command in a process of its own. The demo runs so
    whenever it reaches ROS: rclpy's DDS threads must not live on in the test process, where a
    later fork (flake8's worker pool) could inherit a lock one of them holds, and hang."""
    p = subprocess.run([sys.executable, "-m", "active_recognition.cli", *map(str, argv)],
                       capture_output=True, text=True, timeout=180)
    return p.returncode, p.stdout, p.stderr


def refused(argv, message, capsys=None):
    """The command (in this process with `capsys`, else in its own) exits 2 with one error line
    holding `message`, and no traceback."""
    status, out, err = run(argv, capsys) if capsys else run_process(argv)
    errors = [line for line in err.splitlines() if "error:" in line]
    assert status == 2 and "Traceback" not in err, err
    assert len(errors) == 1 and message in errors[0], err
    return errors[0]


@pytest.fixture(scope="module")
def trained(tmp_path_factory, tiny_tree):
    """A tiny model trained by the CLI on the two-class folder tree."""
    out = tmp_path_factory.mktemp("run") / "run"
    assert main(["train", *TINY_TRAIN, "--root", str(tiny_tree), "--out", str(out)]) == 0
    return out


# ---------------------------------------------------------------- normal paths


def test_render_writes_the_views_and_reports_the_pixels_that_hit(files, tmp_path, capsys):
    out = tmp_path / "sub" / "depth.png"
    status, stdout, _ = run(["render", "--mesh", files / "box.stl", "--views", 4, "--size", 32,
                             "--out", out], capsys)
    depth = DepthCamera(*load_mesh(files / "box.stl"), CameraConfig(32, 32)).render(
        geometry.fibonacci_views(4))
    hit = f"{100 * (depth < 255).mean():.1f}% of pixels hit the mesh"
    assert status == 0 and stdout.strip() == f"wrote {out}: 4 view(s) 32x32, {hit}"
    assert matplotlib.image.imread(out).ndim == 3


def test_dataset_reports_a_class_missing_from_a_split_as_zero(files, tmp_path, capsys):
    sheet, cache = tmp_path / "sheet.png", tmp_path / "cache"
    status, out, err = run(["dataset", "--name", "modelnet", "--root", files / "mn", "--cache-dir",
                            cache, "--contact-sheet", sheet, "--objects-per-class", 3], capsys)
    assert status == 0, err
    rows = [line.split() for line in out.splitlines()]
    assert ["chair", "1", "0", "1"] in rows and ["lamp", "0", "0", "1"] in rows  # train, val, test
    assert ["total", "1", "0", "2"] in rows
    assert "warning: no train objects for class(es) lamp" in err
    assert sheet.stat().st_size > 0 and len(list((cache / "meshes").glob("*.npz"))) == 3


def test_train_then_evaluate_through_the_command(trained, tiny_tree, tmp_path, capsys):
    ckpt = checkpoint.read(trained / "final.pt")
    assert ckpt["classes"] == ["box", "cylinder"] and ckpt["model_args"]["hidden_size"] == 8
    assert checkpoint.read(trained / "last.pt")["state"]["stage"] == 1
    out = tmp_path / "eval"
    status, stdout, err = run(["evaluate", "--dataset", "folder", "--root", tiny_tree,
                               "--checkpoint", trained / "final.pt",
                               "--planners", "random, straight",
                               "--no-shared", "--steps", 3, "--out", out], capsys)
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert json.loads(stdout.splitlines()[-1]) == summary["acc"] and set(summary["acc"]) == {
        "random", "straight"}
    rows = (out / "per_object.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * 3  # header, 3 test objects per planner


@pytest.mark.slow
def test_evaluate_retrains_a_damaged_judge_and_handles_short_episodes(trained, tiny_tree, tmp_path,
                                                                      capsys):
    out = tmp_path / "eval"
    out.mkdir()
    (out / "shared_classifier.pt").write_bytes(b"half a file")
    status, stdout, err = run(["evaluate", "--dataset", "folder", "--root", tiny_tree,
                               "--checkpoint", trained / "final.pt", "--planners", "random",
                               "--steps", 2, "--out", out], capsys)
    assert status == 0, err
    assert "shared_classifier.pt is not usable" in err and "training it again" in err
    assert "episodes of 2 view(s) have no accuracy after 3, 6 or 9 views" in err
    assert (out / "accuracy_vs_views.png").is_file()  # where the note sends the user
    assert checkpoint.read_any(out / "shared_classifier.pt")["kind"] == "shared_multiview"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["acc"] == {"random": {}} and "stderr_3" not in summary  # no 3rd view to score
    assert "| random | - | - | - |" in (out / "report.md").read_text()
    judge = checkpoint.read_any(out / "shared_classifier.pt")
    args = ["evaluate", "--dataset", "folder", "--root", tiny_tree, "--checkpoint",
            trained / "final.pt", "--planners", "random", "--steps", 2, "--out", out]
    status, _, err = run(args, capsys)
    assert status == 0 and "training it again" not in err  # the same shapes: the cache is used
    judge["trained_on"] = "0" * 64  # as if the shapes or the model's camera had changed
    judge.pop("format")
    checkpoint.save(out / "shared_classifier.pt", judge)
    status, _, err = run(args, capsys)
    assert status == 0 and "through another camera or by another recipe: training it again" in err
    assert checkpoint.read_any(out / "shared_classifier.pt")["trained_on"] != "0" * 64


@pytest.mark.slow
def test_a_warning_of_the_package_is_one_line_and_names_no_source_line(trained, tiny_tree, tmp_path):
    """evaluate's readout warning, in a real process: before, Python printed it with the file,
    the line number, 'UserWarning' and the warn() call's source line below it."""
    status, _, err = run_process(["evaluate", "--dataset", "folder", "--root", tiny_tree, "--checkpoint",
                                  trained / "final.pt", "--planners", "random", "--no-shared", "--steps", 2,
                                  "--out", tmp_path / "ev", "--readout", "mean+mirror"])
    assert status == 0, err
    said = [line for line in err.splitlines() if "mirror image too" in line]
    assert len(said) == 1 and said[0].startswith("active-recognition: warning: "), err
    assert "UserWarning" not in err and "warnings.warn(" not in err


def test_warnings_from_elsewhere_keep_their_source():
    own = cli.one_line_warning("careful", UserWarning, cli.__file__, 3)
    assert own == "active-recognition: warning: careful\n"
    foreign = cli.one_line_warning("careful", UserWarning, warnings.__file__, 3)
    assert foreign == warnings.formatwarning("careful", UserWarning, warnings.__file__, 3)
    assert "UserWarning" in foreign and warnings.formatwarning is not cli.one_line_warning
    assert "DeprecationWarning" in cli.one_line_warning("old", DeprecationWarning, cli.__file__, 3)


@pytest.mark.slow
def test_evaluate_scores_with_a_given_judge_as_it_is_and_never_trains_over_it(
        trained, tiny_tree, tmp_path, capsys):
    base = ["evaluate", "--dataset", "folder", "--root", tiny_tree, "--checkpoint", trained / "final.pt",
            "--planners", "random,fixed", "--steps", 3]
    status, first, err = run([*base, "--out", tmp_path / "a"], capsys)
    assert status == 0, err
    judge = tmp_path / "a" / "shared_classifier.pt"
    kept = judge.read_bytes()
    status, again, err = run([*base, "--out", tmp_path / "b", "--judge", judge], capsys)
    assert status == 0 and again.splitlines()[-1] == first.splitlines()[-1], err
    assert not (tmp_path / "b" / "shared_classifier.pt").exists() and judge.read_bytes() == kept
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["acc_shared"] == \
        json.loads((tmp_path / "a" / "summary.json").read_text())["acc_shared"]
    stale = checkpoint.read_any(judge)
    stale["trained_on"] = "0" * 64  # as if trained on other shapes
    stale.pop("format")
    checkpoint.save(tmp_path / "stale.pt", stale)
    kept = (tmp_path / "stale.pt").read_bytes()
    refused([*base, "--out", tmp_path / "c", "--judge", tmp_path / "stale.pt"],
            f"judge {tmp_path / 'stale.pt'} was trained on other shapes, through another camera or by "
            f"another recipe: leave out --judge to train one in --out", capsys)
    assert (tmp_path / "stale.pt").read_bytes() == kept
    refused([*base, "--out", tmp_path / "d", "--judge", tmp_path / "none.pt"],
            f"judge {tmp_path / 'none.pt'}: no such file", capsys)
    assert not (tmp_path / "d").exists()  # refused before any work


def test_train_says_which_checkpoints_it_wrote_and_flags_beat_the_preset(files, tiny_tree,
                                                                         tmp_path, capsys):
    out = tmp_path / "run"
    status, stdout, err = run(["train", "--config", files / "preset.yaml", *TINY_TRAIN, "--root",
                               tiny_tree, "--out", out, "--eval-shapes", 0], capsys)
    assert status == 0, err
    assert stdout.strip().splitlines()[-1] == (f"checkpoints in {out}: pretrained.pt (after pre-training: --stage "
                                               f"joint starts from it), last.pt (resumable), final.pt")
    config = checkpoint.read(out / "final.pt")["config"]
    assert config["joint_epochs"] == 1 and config["steps"] == 2 and config["lr_joint"] == 0.001


@pytest.mark.slow
def test_demo_recognises_an_object_over_ros():
    import_ros("rclpy")
    status, out, err = run_process(["demo", "--objects", 2, "--time-budget", 2.5])
    assert status == 0, err
    assert "object 1/2: true=" in out and "accuracy" in out.splitlines()[-1]
    assert "mean robot seconds" in out.splitlines()[-1] and "(budget 2.5 s)" in out.splitlines()[-1]
    spent = [(int(line.split("views=")[1].split()[0]), float(line.split("robot=")[1].split()[0]))
             for line in out.splitlines() if "robot=" in line]
    assert len(spent) == 2 and all(s <= 2.5 or views == 1 for views, s in spent), out  # within the budget


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("argv,message", [
    (["--mesh", "{files}/noise.obj"], "noise.obj: not a text OBJ file"),
    (["--mesh", "{files}/lie.ply"], "lie.ply: header declares 3 vertices and 1000 faces"),
    (["--mesh", "{files}/missing.stl"], "missing.stl: no such file"),
    (["--mesh", "{files}/a_dir"], "a_dir: is a directory, not a file"),
    (["--theta", "nan"], "argument --theta: must be a finite number, got 'nan'"),
    (["--phi", "inf"], "argument --phi: must be a finite number, got 'inf'"),
    (["--views", "-3"], "argument --views: must be an integer from 0 to 100, got '-3'"),
    (["--views", "1e9"], "argument --views: must be an integer from 0 to 100, got '1e9'"),
    (["--size", "0"], "argument --size: must be an integer from 1 to 1024, got '0'"),
    (["--radius", "-1"], "argument --radius: must be a finite number in (0, 100], got '-1'"),
    (["--fov", "200"], "argument --fov: must be a finite number in (0, 180), got '200'"),
    (["--out", "{files}/a_dir"], "--out {files}/a_dir: is a directory; name a file"),
    (["--out", "{files}/depth.jpg"], "--out {files}/depth.jpg: must end in .png"),
    (["--out", "{files}/a_file/x.png"], "{files}/a_file: exists and is not a directory"),
])
def test_render_refuses(files, capsys, argv, message):
    argv = [a.format(files=files) for a in argv]
    base = {"--mesh": str(files / "box.stl"), "--out": str(files / "unused.png")}
    for flag, value in zip(argv[::2], argv[1::2]):
        base[flag] = value
    argv = ["render", *[x for kv in base.items() for x in kv]]
    refused(argv, message.format(files=files), capsys)
    assert not (files / "unused.png").exists()


@pytest.mark.parametrize("argv,message", [
    (["--name", "folder", "--root", "{files}/mn"], "no objects (train or test) found in folder"),
    (["--name", "modelnet", "--root", "{files}/nothing"], "nothing: no such directory"),
    (["--name", "modelnet", "--root", "{files}/a_file"], "a_file: is not a directory"),
    (["--name", "modelnet"], "the modelnet dataset needs its root folder (--root DIR; a node's parameter root)"),
    (["--name", "modelnet", "--root", "{files}/a_dir"], "has no <class>/train/ or <class>/test/"),
    (["--name", "procedural", "--root", "{files}/mn"], "the procedural dataset is generated"),
    (["--name", "imagenet"], "argument --name: invalid choice: 'imagenet'"),
    (["--cache-dir", "{files}/a_file"], "--cache-dir {files}/a_file: exists and is not a dir"),
    (["--cache-dir", "{files}/c", "--no-cache"], "not allowed with argument"),
    (["--contact-sheet", "{files}/a_dir"], "--contact-sheet {files}/a_dir: is a directory"),
    (["--contact-sheet", "{files}/sheet.pdf"], "--contact-sheet {files}/sheet.pdf: must end in .png"),
    (["--contact-sheet", ""], "--contact-sheet '': not a file name"),
    (["--cache-dir", ""], "--cache-dir: empty path"),
    (["--objects-per-class", "0"], "argument --objects-per-class: must be an integer from 1 to 20"),
    (["--views-per-object", "9"], "argument --views-per-object: must be an integer from 1 to 5"),
    (["--seed", "-1"], "argument --seed: must be an integer from 0 to 4294967295, got '-1'"),
    (["--name", "modelnet", "--root", "{files}/nothing", "--contact-sheet", "{files}/s.png", "--sheet-split",
      "cross"], "--sheet-split cross: the held-out styles are a generated benchmark's (procedural, twins); "
                "modelnet has test"),
])
def test_dataset_refuses(files, capsys, argv, message):
    argv = ["dataset", *[a.format(files=files) for a in argv]]
    refused(argv, message.format(files=files), capsys)


@pytest.mark.parametrize("argv,message", [
    (["--config", "{files}/syntax.yaml"], "--config {files}/syntax.yaml, line 2, column 15"),
    (["--config", "{files}/nested.yaml"], "unknown option model.hiden_size (did you mean "
                                          "model.hidden_size?)"),
    (["--config", "{files}/words.yaml"], "pretrain_epochs must be an integer from 0 to 100000, "
                                         "got 'many'"),
    (["--config", "{files}/model5.yaml"], "model must be a mapping of ModelConfig options"),
    (["--config", "{files}/a_dir"], "--config {files}/a_dir: is a directory, not a file"),
    (["--config", "{files}/missing.yaml"], "--config {files}/missing.yaml: no such file"),
    (["--config", ""], "--config: empty path"),
    (["--out", "{files}/a_file"], "out {files}/a_file: exists and is not a directory"),
    (["--device", "tpu9"], "argument --device: must be cpu, cuda or cuda:N, got 'tpu9'"),
    (["--checkpoint-every", "0"], "argument --checkpoint-every: must be an integer >= 1, got '0'"),
    (["--hidden-size", "0"], "argument --hidden-size: must be an integer from 1 to 8192, got '0'"),
    (["--max-step", "-1"], "argument --max-step: must be a finite number in (0, 3.14159]"),
    (["--lr-pretrain", "nan"], "argument --lr-pretrain: must be a finite number > 0, got 'nan'"),
    (["--lr-joint", "-1"], "argument --lr-joint: must be a finite number > 0, got '-1'"),
    (["--pretrain-epochs", "-1"], "argument --pretrain-epochs: must be an integer from 0 to"),
    (["--pretrain-epochs", "0", "--joint-epochs", "0"], "nothing to train"),
    (["--batch-size", "0"], "argument --batch-size: must be an integer from 1 to 100000"),
    (["--seed", "-1"], "argument --seed: must be an integer from 0 to 4294967295"),
    (["--initial-step", "0", "nan"], "argument --initial-step: must be a finite number, got 'nan'"),
    (["--initial-step", "0", "0.9"], "initial step [0.0, 0.9] must lie inside the increment bound"),
    (["--policy", "imitation"], "policy imitation needs a view-scoring head"),
    (["--imitation-mix", "1.5"], "argument --imitation-mix: must be a finite number in [0, 1]"),
    (["--resume", "--out", "{files}/fresh_run"], "nothing to resume"),
    (["--dataset", "folder", "--out", "{files}/fresh_run"], "folder dataset needs its root folder"),
    (["--dataset", "folder", "--root", "{files}/one", "--out", "{files}/fresh_run"],
     "1 class ['a']; recognising needs at least 2"),
    (["--out", "/proc/no_run_here"], "out /proc/no_run_here: cannot write there"),
])
def test_train_refuses(files, capsys, argv, message):
    refused(["train", *[a.format(files=files) for a in argv]], message.format(files=files), capsys)
    assert not (files / "fresh_run" / "last.pt").exists()


@pytest.mark.parametrize("command", ["render", "dataset", "train", "evaluate", "demo"])
def test_help_at_80_columns_breaks_no_word(monkeypatch, command):
    """argparse wraps help at spaces; a word longer than the column (a list joined without
    spaces) it cuts in two, which reads as two wrong names."""
    monkeypatch.setenv("COLUMNS", "80")
    sub = cli.build_parser()._subparsers._group_actions[0].choices[command]
    shown = set(sub.format_help().split())
    for action in sub._actions:
        words = (action.help or "").replace("%%", "%").split()
        assert all(w in shown for w in words), (action.option_strings, [w for w in words if w not in shown])


@pytest.mark.parametrize("argv,message", [
    (["--objects", "-1"], "argument --objects: must be an integer >= 0, got '-1'"),
    (["--objects", "4"], "objects = 4, but the folder test split holds 3 (0 = all of them)"),
    (["--starts", "0"], "argument --starts: must be an integer from 1 to 50, got '0'"),
    (["--starts", "51"], "argument --starts: must be an integer from 1 to 50, got '51'"),
    (["--steps", "0"], "argument --steps: must be an integer from 1 to 100, got '0'"),
    (["--entropy-threshold", "nan"], "argument --entropy-threshold: must be a finite number >= 0"),
    (["--planners", "psychic"], "argument --planners: must be one of learned, random, straight"),
    (["--planners", "random,psychic"], "argument --planners: must be one of learned, random, straight, "
                                       "reinforce, fixed, imitation, fixed+imitation, oracle, greedy, got 'psychic'"),
    (["--planners", ","], "argument --planners: must be one of"),
    (["--planners", "random,random"], "planners: random named more than once"),
    (["--planners", "reinforce"], "the reinforce planner needs --reinforce-checkpoint"),
    (["--planners", "imitation"], "the imitation planner needs a model with a view-scoring head"),
    (["--checkpoint", "{files}/a_dir"], "checkpoint {files}/a_dir: is a directory, not a file"),
    (["--checkpoint", "{files}/missing.pt"], "checkpoint {files}/missing.pt: no such file"),
    (["--checkpoint", "{files}/box.stl"], "box.stl: unreadable: not a torch checkpoint file"),
    (["--checkpoint", "{files}/nan.pt"], "nan.pt: weight classify.weight holds NaN or infinite"),
    (["--checkpoint", "{files}/empty.pt"], "empty.pt: unreadable: not a torch checkpoint file"),
    (["--checkpoint", "{files}/truncated.pt"], "truncated.pt: unreadable"),
    (["--checkpoint", "{shipped}"], "the checkpoint's classes ['bathtub', 'bed'"),
    (["--planner-checkpoint", "learned"], "--planner-checkpoint 'learned': expected PLANNER=FILE"),
    (["--planner-checkpoint", "psychic={files}/nan.pt"], "psychic={files}/nan.pt: no such planner"),
    (["--learned-metrics", "{files}/missing.csv", "--reinforce-metrics", "{files}/missing.csv"],
     "metrics {files}/missing.csv: no such file"),
    (["--learned-metrics", "{files}/box.stl", "--reinforce-metrics", "{files}/box.stl"],
     "metrics {files}/box.stl: not a text file"),
    (["--learned-metrics", "{files}/preset.yaml"], "--learned-metrics and --reinforce-metrics go "
                                                   "together"),
    (["--learned-metrics", ""], "--learned-metrics and --reinforce-metrics go together"),
    (["--learned-metrics", "", "--reinforce-metrics", ""], "metrics: empty path"),
    (["--out", "{files}/a_file"], "out {files}/a_file: exists and is not a directory"),
    (["--split", "dev"], "argument --split: invalid choice: 'dev'"),
])
def test_evaluate_refuses_before_any_work(files, trained, tiny_tree, capsys, argv, message):
    fill = {"files": files, "shipped": checkpoint.shipped("procedural")}
    base = ["evaluate", "--dataset", "folder", "--root", tiny_tree, "--checkpoint",
            trained / "final.pt", "--planners", "random", "--no-shared", "--out", files / "ev"]
    refused(base + [a.format(**fill) for a in argv], message.format(**fill), capsys)
    assert not (files / "ev" / "report.md").exists()


@pytest.mark.slow
@pytest.mark.parametrize("argv,message", [
    (["--objects", "0"], "argument --objects: must be an integer from 1 to 100000, got '0'"),
    (["--objects", "-2"], "argument --objects: must be an integer from 1 to 100000, got '-2'"),
    (["--objects", "100000"], "objects must be 1..500 (procedural test split), got 100000"),
    (["--seed", "-1"], "argument --seed: must be an integer from 0 to 4294967295"),
    (["--checkpoint", "{files}/missing.pt"], "checkpoint {files}/missing.pt: no such file"),
    (["--dataset", "twins", "--checkpoint", "{shipped}"], "its classes ['bathtub', 'bed'"),
    (["--planner", "oracle"], "argument --planner: invalid choice: 'oracle'"),
    (["--record", "{files}/run.txt"], "record: '{files}/run.txt' must be a file name ending in .mcap"),
    (["--record", "{files}/nowhere/run.mcap"], "folder '{files}/nowhere' does not exist"),
])
def test_demo_refuses(files, capsys, argv, message):
    import_ros("rclpy")
    fill = {"files": files, "shipped": checkpoint.shipped("procedural")}
    argv = ["demo", *[a.format(**fill) for a in argv]]
    # a bad --record is found when the nodes start: in a process of its own (see run_process)
    refused(argv, message.format(**fill), None if "--record" in argv else capsys)


@pytest.mark.slow
@pytest.mark.parametrize("argv,message", [
    (["train", "--config", "{files}/syntax.yaml"], "line 2, column 15: mapping values are not"),
    (["render", "--mesh", "{files}/box.stl", "--theta", "nan"], "must be a finite number"),
    (["evaluate", "--objects", "-1"], "argument --objects: must be an integer >= 0"),
])
def test_the_installed_command_exits_2_with_one_line(files, argv, message):
    """The same through a real process: exit status 2, stderr one line, no traceback."""
    status, out, err = run_process([a.format(files=files) for a in argv])
    assert status == 2 and out == ""
    assert len(err.splitlines()) == 1 and message in err, err


@pytest.mark.parametrize("argv,message", [
    (["--checkpoint", "{tmp}/none.pt", "--dataset", "procedural"], "none.pt: no such file"),
    (["--dataset", "procedural", "--score", "msp"], "argument --score: invalid choice"),
])
def test_open_set_fit_is_a_subcommand_that_refuses_in_one_line(tmp_path, capsys, argv, message):
    """The unknown answer's fit (unknown/fit.py) as `active-recognition open-set-fit`: bad input
    ends before any work, in one line."""
    refused(["open-set-fit", *[a.format(tmp=tmp_path) for a in argv]], message, capsys)
