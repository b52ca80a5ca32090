# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""flake8 as ROS 2 Jazzy's ament_flake8 runs it, in the house style of setup.cfg [flake8]."""
from pathlib import Path

import pytest
from ament_flake8.main import main_with_errors

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.flake8
@pytest.mark.linter
def test_flake8(monkeypatch):
    monkeypatch.chdir(ROOT)  # ament_flake8 walks the working directory for folders to skip
    rc, errors = main_with_errors(argv=[".", "--config", str(ROOT / "setup.cfg"),
                                        "--exclude", "build", "install", "log"])
    assert rc == 0, f"Found {len(errors)} code style errors / warnings:\n" + "\n".join(errors)


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8_reports_a_breach_of_the_house_style(monkeypatch, tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import os\nx = 'single'\n" + "y = 1  # " + "-" * 120 + "\n")
    monkeypatch.chdir(tmp_path)
    rc, errors = main_with_errors(argv=[str(bad), "--config", str(ROOT / "setup.cfg")])
    codes = sorted({e.split(": ")[1].split()[0] for e in errors})
    assert rc == 1 and codes == ["E501", "F401", "Q000"], errors
