#!/usr/bin/env bash
# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

# Keep N cores busy (default: all, `nproc`) for S seconds (default 900), as a robot's other work
# would, then stop by itself; a kill (TERM, Ctrl-C) stops it and its workers sooner. Each worker
# runs under `timeout`, so none outlives S even where this script is killed with -9.
#   bash tools/load.sh --seconds 900 &   then run the tests; kill %1 (or let it end)
set -euo pipefail
usage="usage: tools/load.sh [--cores N] [--seconds S]"
cores=$(nproc) seconds=900
while [ $# -gt 0 ]; do
  case "$1" in
    --cores) cores=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
[[ "$cores" =~ ^[1-9][0-9]*$ && "$seconds" =~ ^[1-9][0-9]*$ ]] || { echo "$usage (positive integers)" >&2; exit 2; }
workers=()
trap 'kill "${workers[@]}" 2>/dev/null; wait; exit 143' INT TERM  # after its workers
for _ in $(seq "$cores"); do
  timeout "$seconds" sh -c 'while :; do :; done' &
  workers+=($!)
done
echo "load: $cores busy cores for $seconds s (pid $$)" >&2
wait "${workers[@]}" || true
