# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Checkpoints as plain dicts, written atomically and loaded with weights_only=True.

{'format', 'model', 'model_args', 'classes', 'optimizer', 'state', 'config', 'elapsed'}, and
'size_prior' where the training set knew its objects' sizes (size_prior.py), 'open_set' where
its unknown answer was fitted (unknown/fit.py); 'members' (and 'judges', 'member_files') where it
is an ensemble of that many networks (ensemble.py)
"""
from __future__ import annotations

import math
import pickle
import zipfile
from pathlib import Path

import torch

from active_recognition.argument_checks import InputError, check_mapping
from active_recognition.atomic_files import atomic_write
from active_recognition.model.ensemble import Ensemble, EnsembleConfig
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.size_prior import SizePrior
from active_recognition.unknown.thresholds import checked_open_set

FORMAT = "active_recognition/1"
MODELS = Path(__file__).parents[1] / "checkpoints"  # the shipped models
SHIPPED_FOR = {"procedural": "procedural.pt", "twins": "twins.pt", "modelnet": "modelnet10.pt"}
DEFAULT_DATASET = "procedural"  # where a caller names neither a model nor a dataset


def shipped(dataset=DEFAULT_DATASET):
    """The shipped model of a dataset (modelnet: ModelNet10's)."""
    if dataset not in SHIPPED_FOR:
        raise InputError(f"shipped models exist for {', '.join(SHIPPED_FOR)}, not {dataset!r}")
    return MODELS / SHIPPED_FOR[dataset]


def model_path(path=None, dataset=DEFAULT_DATASET):
    """The model file to read. The one rule for a missing one: no `path` (None or "") means the
    shipped model of the dataset whose objects the model will see. The recognizer node's are
    real objects (modelnet: modelnet10.pt); evaluate's and the demo's come from their dataset; a
    library call that names none gets procedural.pt, the package's own objects. A shipped
    model's bare file name (procedural.pt, twins.pt, modelnet10.pt) names that model unless a
    file of that name lies in the working folder: how a launch file or a node's parameter
    names one, as the models install with the Python package, not in its share."""
    if path:
        if str(path) in SHIPPED_FOR.values() and not Path(path).exists():
            return MODELS / str(path)
        return Path(path)
    if dataset not in SHIPPED_FOR:
        raise InputError(f"no model file given, and none is shipped for the {dataset} dataset "
                         f"(only for {', '.join(SHIPPED_FOR)}): name a checkpoint")
    return shipped(dataset)


class CheckpointError(InputError):
    """A checkpoint file that is not ours or does not fit; the message says which and why."""

    def __init__(self, path, reason):
        super().__init__(f"checkpoint {path}: {reason}")
        self.path, self.reason = path, reason

    def __reduce__(self):  # crosses a process pool as itself (pickle would call __init__(message))
        return type(self), (self.path, self.reason)


def save(path, payload):
    """Write `payload` to `path` atomically (files.atomic_write): never a half-written file."""
    with atomic_write(path, "wb") as f:
        torch.save({"format": FORMAT, **payload}, f)


def update(path, out=None, **fields):
    """Rewrite the model checkpoint at `path` with `fields` set, to `out` (default: `path`
    itself), atomically; everything else it holds is kept."""
    ckpt = read(path)
    ckpt.pop("format")
    save(out or path, {**ckpt, **fields})


def read(path):
    """Load a model checkpoint dict safely; CheckpointError for anything that is not ours."""
    ckpt = read_any(path)
    if ckpt.get("kind", "model") != "model":
        raise CheckpointError(path, f"holds a {ckpt['kind']}, not a recognition model")
    return ckpt


def read_any(path):
    """Load any of our checkpoint dicts (models, shared classifiers) safely."""
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(path, "is a directory, not a file" if path.is_dir() else "no such file")
    if not zipfile.is_zipfile(path):
        raise CheckpointError(path, "unreadable: not a torch checkpoint file (truncated or foreign)")
    try:
        ckpt = torch.load(path, map_location="cpu", weights_only=True)
    except pickle.UnpicklingError as e:
        raise CheckpointError(path, f"refused: not a plain-weights checkpoint ({str(e)[:200]})") from None
    except Exception as e:  # truncated zip, not a torch file, ...
        raise CheckpointError(path, f"unreadable ({type(e).__name__}: {str(e)[:200]})") from None
    if not isinstance(ckpt, dict) or ckpt.get("format") != FORMAT:
        raise CheckpointError(path, f"not an active_recognition checkpoint (format {FORMAT} expected)")
    for key in ("model", "model_args", "classes"):
        if key not in ckpt:
            raise CheckpointError(path, f"missing {key!r}")
    return ckpt


def build_model(ckpt, path="<checkpoint>"):
    """The model a checkpoint dict describes, with its weights; CheckpointError on any mismatch."""
    try:
        config = ModelConfig(**check_mapping(ModelConfig, ckpt["model_args"], "model_args."))
    except InputError as e:
        raise CheckpointError(path, f"bad model_args ({e})") from None
    ensemble = "members" in ckpt
    if ensemble:  # EnsembleConfig checks the number of members and the judges
        try:
            config = EnsembleConfig(**config.to_dict(), members=ckpt["members"], judges=ckpt.get("judges", []))
        except InputError as e:
            raise CheckpointError(path, str(e)) from None
    classes = ckpt["classes"]
    if not isinstance(classes, list) or len(classes) != config.num_classes:
        raise CheckpointError(path, f"{len(classes) if isinstance(classes, list) else '?'} class "
                                    f"names for a model of {config.num_classes} classes")
    model = Ensemble(config) if ensemble else RecurrentAttention(config)
    try:
        model.load_state_dict(ckpt["model"], strict=True)
    except (RuntimeError, TypeError, AttributeError) as e:
        raise CheckpointError(path, f"weights do not fit the model ({str(e)[:300]})") from None
    name = nonfinite(model.state_dict())
    if name is not None:
        raise CheckpointError(path, f"weight {name} holds NaN or infinite values (a diverged run?)")
    if "size_prior" in ckpt:  # what the object's size says of its class (size_prior.py)
        try:
            model.size_prior = SizePrior.from_dict(ckpt["size_prior"], config.num_classes)
        except InputError as e:
            raise CheckpointError(path, str(e)) from None
    if "open_set" in ckpt:  # the prototypes and threshold of its `unknown` answer (unknown/fit.py)
        try:
            model.open_set = checked_open_set(ckpt["open_set"], config.num_classes, config.state_size)
        except InputError as e:
            raise CheckpointError(path, str(e)) from None
    return model


def nonfinite(state_dict):
    """The name of the first floating-point tensor holding NaN or inf, else None."""
    for name, value in state_dict.items():
        if torch.is_tensor(value) and value.is_floating_point() and not torch.isfinite(value).all():
            return name
    return None


STATE = ("stage", "epoch", "batch", "step")  # where a run is (a resumable checkpoint's "state")


def read_fitting(path, config: ModelConfig, classes, resumable=False, grow_loc=False):
    """A checkpoint of this run's model (same options and classes; `resumable`: with its training
    state), to resume from or to start the joint stage from; CheckpointError naming what differs.
    `grow_loc`: a checkpoint without FC_loc's hidden layer fits a run with one (loc_hidden)."""
    ckpt = read(path)
    if "members" in ckpt:
        raise CheckpointError(path, "is an ensemble of trained networks (ensemble.py): training continues a single one")
    build_model(ckpt, path)  # its own weights are sound
    if list(ckpt["classes"]) != list(classes):
        raise CheckpointError(path, f"classes {ckpt['classes']} are not the dataset's {list(classes)}")
    theirs, ours = ModelConfig(**ckpt["model_args"]).to_dict(), config.to_dict()
    grown = grow_loc and theirs["loc_hidden"] == 0
    differ = [f"{k} {theirs[k]!r}, this run {ours[k]!r}" for k in ours
              if theirs[k] != ours[k] and not (grown and k in ("loc_hidden", "loc_step"))]
    if differ:
        raise CheckpointError(path, "written with other model options (" + "; ".join(differ) +
                                    "): use the same options, or another --out")
    state = ckpt.get("state")
    if resumable and not (isinstance(state, dict) and isinstance(ckpt.get("optimizer"), dict)
                          and all(type(state.get(k)) is int and state[k] >= 0 for k in STATE)
                          and type(ckpt.get("elapsed")) in (int, float)):
        raise CheckpointError(path, "holds no training state to resume from")
    return ckpt


# the settings that fix a run's batches and episodes: a resume with others would not continue it
RESUME_FIXED = ("dataset", "seed", "batch_size", "views_per_shape", "max_shapes", "policy", "steps")


def check_resume_settings(path, saved, config):
    """CheckpointError when the run at `path` was trained with other RESUME_FIXED settings than
    `config` (dicts of TrainConfig; a checkpoint without its config is taken as it is)."""
    if not isinstance(saved, dict):
        return
    differ = [f"{k} {saved[k]!r}, this run {config[k]!r}" for k in RESUME_FIXED
              if k in saved and saved[k] != config[k]]
    if differ:
        raise CheckpointError(path, "was trained with other settings (" + "; ".join(differ) + "): resume with "
                                    "the run's own, or start afresh in another --out")


def load_model(path=None, expect_classes=None, dataset=DEFAULT_DATASET):
    """(model in eval mode, class names, checkpoint dict) from a file (none: model_path's rule)."""
    path = model_path(path, dataset)
    ckpt = read(path)
    model = build_model(ckpt, path)
    if expect_classes is not None and list(expect_classes) != list(ckpt["classes"]):
        raise CheckpointError(path, f"classes {ckpt['classes']} differ from {list(expect_classes)}")
    return model.eval(), list(ckpt["classes"]), ckpt


def stop_if_diverged(model, where, ckpt_path, saved, loss=None):
    """InputError when `loss` (if given), else any weight, is not finite: training has diverged.
    The message says where and which checkpoint is the last good one (none is overwritten)."""
    if loss is not None:
        bad = None if math.isfinite(loss) else f"the loss became {loss}"
    else:
        name = nonfinite(model.state_dict())
        bad = None if name is None else f"weight {name} became non-finite"
    if bad is None:
        return
    last = (f"the last good checkpoint is {ckpt_path} (step {saved})" if saved is not None else
            "no checkpoint had been written yet")
    raise InputError(f"training stopped at {where}: {bad} (is a learning rate too high?); {last}")
