# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""tools/build_interfaces.sh on bad sources: a missing folder or archive, a corrupt archive, a
package that fails to build. Each ends with one line naming what failed and a status not 0, and
leaves what was installed before as it was (the build goes to a staging folder first), so the
next run and the ros2 command line still work."""
import os
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest
from ros2_cli import need_ros2, ros2

ROOT = Path(__file__).resolve().parents[1]


def build(*args, where=None, deps=None):
    """The script run with ARGS, its build folders under `where` (a test's own) and its archives
    in `deps` (instead of ../shared/deps) if given."""
    env = {**os.environ, "PYTHON": sys.executable, **({"BUILD_INTERFACES_DIR": str(where)} if where else {}),
           **({"BUILD_INTERFACES_DEPS": str(deps)} if deps else {})}
    return subprocess.run(["bash", str(ROOT / "tools" / "build_interfaces.sh"), *args], capture_output=True,
                          text=True, env=env, timeout=600)


def error_lines(done):
    return [line for line in done.stderr.splitlines() if line.strip()]


@pytest.fixture(scope="module")
def installed():
    need_ros2()
    checked = build("--check")  # else a run here would rebuild them, beside other tests
    assert checked.returncode == 0, f"run bash tools/build_interfaces.sh first:\n{checked.stdout}"
    before = ros2("pkg", "executables", "active_recognition").stdout
    yield before
    # what the set-up installed is still whole: the package found, the command line working
    assert ros2("pkg", "executables", "active_recognition").stdout == before


def test_a_source_that_does_not_exist_is_named(installed, tmp_path):
    done = build("--ros2cli", str(tmp_path / "nowhere.tar.gz"))
    assert done.returncode == 2
    assert error_lines(done) == [f"build_interfaces: --ros2cli {tmp_path / 'nowhere.tar.gz'}: no such folder "
                                 f"or archive"]


@pytest.mark.slow
def test_a_corrupt_archive_is_named_and_nothing_is_installed(installed, tmp_path):
    bad = tmp_path / "ros2cli.tar.gz"
    bad.write_bytes(b"\x1f\x8b\x08\x00 not really gzip" * 10)
    done = build("--ros2cli", str(bad), where=tmp_path / "build")
    assert done.returncode == 1, done
    [line] = error_lines(done)
    assert line.startswith(f"build_interfaces: ros2cli failed: {bad} is not a readable .tar.gz"), line
    assert "ros2cli up to date" in build("--check").stdout  # the earlier install stands, whole


@pytest.mark.slow
def test_a_package_that_fails_to_build_is_named_and_nothing_is_installed(installed, tmp_path):
    package = tmp_path / "src" / "ros2cli"
    package.mkdir(parents=True)
    (package / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>ros2cli</name><version>9.9.9</version>'
        "<description>broken</description><maintainer email='a@b.invalid'>a</maintainer>"
        "<license>Apache-2.0</license><export><build_type>ament_python</build_type></export></package>\n")
    (package / "setup.py").write_text("raise SystemExit('this package does not build')\n")
    archive = tmp_path / "broken.tar.gz"
    with tarfile.open(archive, "w:gz") as tar:
        tar.add(tmp_path / "src", arcname="src")
    done = build("--ros2cli", str(archive), where=tmp_path / "build")
    assert done.returncode == 1, done
    [line] = error_lines(done)
    assert line.startswith("build_interfaces: ros2cli failed to build (ros2cli); nothing was installed; the log:"), line
    assert "ros2cli up to date" in build("--check").stdout


def test_without_the_archives_what_was_built_is_kept_and_the_rest_goes_on(installed, tmp_path):
    done = build("--check", deps=tmp_path / "no-deps")
    assert done.returncode == 0, done
    for name in ("tf2_ros_py", "ros2cli"):
        assert f"build_interfaces: {name} kept as it is in " in done.stdout, done.stdout
    assert "vision_msgs up to date" in done.stdout
