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

"""Where training runs: the CPU, a GPU, or one rank of several under torchrun."""
import os
import sys

import torch
import torch.distributed as dist

from .validation import InputError


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
