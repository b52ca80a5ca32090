# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where training runs: the CPU, a GPU, or one rank of several under torchrun."""
import ctypes
import os
import sys

import torch
import torch.distributed as dist

from active_recognition.argument_checks import InputError


def distributed(device="cpu"):
    """(rank, world) and the process group, when started by torchrun: nccl on GPU, gloo on CPU."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    rank = int(os.environ.get("RANK", "0"))
    if world > 1 and not dist.is_initialized():
        dist.init_process_group("nccl" if device.startswith("cuda") else "gloo")
    return rank, world


def resolve_device(device, rank):
    """cuda on a torchrun rank means that rank's own GPU (LOCAL_RANK)."""
    if device == "cuda" and int(os.environ.get("WORLD_SIZE", "1")) > 1:
        return f"cuda:{int(os.environ.get('LOCAL_RANK', rank))}"
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise InputError(f"device {device!r} asked for, but torch sees no CUDA GPU")
    return device


PRECISIONS = ("auto", "float32", "bfloat16")


def teacher_dtype(precision, device):
    """The dtype imitation's teacher runs the encoder in over the candidate views (no gradient
    flows there: it only ranks them), or None for float32. `auto`: bfloat16 on a GPU that has
    it and on a CPU where oneDNN runs bfloat16 kernels (AVX-512; about 1.8x the float32 rate
    for the wide encoder here), float32 elsewhere (AVX2, where bfloat16 would be slower)."""
    if precision not in PRECISIONS:
        raise InputError(f"teacher_precision must be one of {PRECISIONS}, got {precision!r}")
    if precision == "float32":
        return None
    if precision == "bfloat16":
        return torch.bfloat16
    if torch.device(device).type == "cuda":
        return torch.bfloat16 if torch.cuda.is_bf16_supported() else None
    try:
        native = bool(torch.ops.mkldnn._is_mkldnn_bf16_supported())
    except (AttributeError, RuntimeError):  # a build without oneDNN's check
        native = False
    return torch.bfloat16 if native else None


_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3  # glibc's malloc.h


def keep_freed_memory():
    """Let this process's malloc keep what it frees for the next ask, where it is glibc's.

    A training step frees and asks again for the same large blocks each time (the rendered
    candidates, torch's activations). glibc by default maps each block of 128 KiB or more
    afresh from the kernel and gives it back when freed, and trims its heap, so every step
    faulted the same pages in again, with the two render threads taking the kernel's lock in
    turn. With blocks up to 32 MiB (glibc's most) served from the heap and up to 256 MiB of
    free memory kept, on a 2-core AVX-512 machine, one process each way: a ModelNet10 joint step
    0.86-0.92 -> 0.72-0.79 s, the 1,600 candidates' render 185 -> 156 ms, the same numbers.
    True where it took; elsewhere (another C library) nothing changes."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    # the mmap threshold first: setting any of these stops glibc adapting it on its own
    return all(mallopt(option, value) == 1 for option, value in
               ((_M_MMAP_THRESHOLD, 32 << 20), (_M_TRIM_THRESHOLD, 256 << 20), (_M_TOP_PAD, 64 << 20)))


def finish_distributed():
    """Under torchrun: leave the process group cleanly, then exit at once."""
    if not dist.is_initialized():
        return
    dist.barrier()
    dist.destroy_process_group()
    # A finished torchrun worker sometimes aborted during interpreter teardown ("terminate called
    # without an active exception", a C++ thread of gloo or embree); everything is written and
    # flushed by now, so skip the teardown.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def training_layout(model, device):
    """`model` with its convolutions' weights channels-last on a CPU, so oneDNN runs them in its
    own layout (a single-channel image is both layouts at once): the same numbers to float
    precision, about a quarter less time in the wide encoder's forward and backward
    (benchmarks/training_throughput.py). Left as it is on a GPU."""
    return model.to(memory_format=torch.channels_last) if torch.device(device).type == "cpu" else model
