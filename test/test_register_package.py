# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""tools/register_package.sh into an environment that has never held the package's index entries
(as in CI's fresh venv): it writes the marker, one link a file and the .pth line; a second run
finds it up to date; a link whose file is gone is removed. The environment is a bare venv whose
site-packages reach this one's (a .pth line), with stand-in console scripts."""
import os
import subprocess
import sysconfig
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def register(python):
    return subprocess.run(["bash", str(ROOT / "tools" / "register_package.sh")], capture_output=True, text=True,
                          env={**os.environ, "PYTHON": str(python)}, timeout=120)


def test_register_into_a_fresh_environment(tmp_path):
    prefix = tmp_path / "env"
    venv.create(prefix, with_pip=False)
    python = prefix / "bin" / "python"
    site = Path(subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    (site / "reach.pth").write_text(f"{ROOT}\n{sysconfig.get_paths()['purelib']}\n")
    for exe in ("recognizer", "simulated_camera"):
        (prefix / "bin" / exe).write_text("#!/bin/sh\n")
        (prefix / "bin" / exe).chmod(0o755)
    assert not (prefix / "share" / "active_recognition").exists()

    done = register(python)
    assert done.returncode == 0, done.stderr
    assert "registered" in done.stdout
    assert (prefix / "share/ament_index/resource_index/packages/active_recognition").is_file()
    share = prefix / "share" / "active_recognition"
    assert (share / "package.xml").resolve() == ROOT / "package.xml"
    launches = sorted(p.name for p in (ROOT / "launch").glob("*.launch.*"))
    assert sorted(p.name for p in (share / "launch").iterdir()) == launches
    assert all((share / "launch" / name).is_symlink() for name in launches)
    assert (prefix / "lib/active_recognition/recognizer").resolve() == prefix / "bin" / "recognizer"
    # a Python of the environment started with nothing set finds the prefix
    env = {k: v for k, v in os.environ.items() if k != "AMENT_PREFIX_PATH"}
    seen = subprocess.run([python, "-c", "import os; print(os.environ['AMENT_PREFIX_PATH'])"],
                          capture_output=True, text=True, env=env, check=True).stdout.strip()
    assert Path(seen) == prefix

    again = register(python)
    assert again.returncode == 0 and "up to date" in again.stdout, again.stdout + again.stderr

    stale = share / "launch" / "gone.launch.xml"
    stale.symlink_to(tmp_path / "nothing")
    third = register(python)
    assert third.returncode == 0 and "registered" in third.stdout, third.stderr
    assert not stale.is_symlink()
