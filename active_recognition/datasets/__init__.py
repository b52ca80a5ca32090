"""Shape datasets: ModelNet, ShapeNetCore, a plain folder, and the embedded benchmarks
(procedural, twins)."""
from __future__ import annotations

from ..validation import InputError
from .base import ShapeDataset, default_cache_dir
from .folder import folder
from .modelnet import modelnet
from .procedural import procedural
from .shapenet import shapenet
from .twins import twins

NAMES = ("procedural", "twins", "modelnet", "shapenet", "folder")
GENERATED = {"procedural": procedural, "twins": twins}


def open_dataset(name, root=None, split="train", cache_dir=None, validate=True, **kwargs):
    """Open a split of a dataset by name; file datasets are validated (bad files skipped)."""
    if name in GENERATED:
        if root:
            raise InputError(f"the {name} dataset is generated: it takes no root folder "
                             f"(got {root}); roots are for modelnet, shapenet and folder")
        return GENERATED[name](split, cache_dir=cache_dir, **kwargs)
    loaders = {"modelnet": modelnet, "shapenet": shapenet, "folder": folder}
    if name not in loaders:
        raise InputError(f"dataset must be one of {', '.join(NAMES)}, got {name!r}")
    ds = loaders[name](root, split, cache_dir=cache_dir, **kwargs)
    return ds.validate() if validate else ds


__all__ = ["ShapeDataset", "open_dataset", "default_cache_dir", "NAMES"]
