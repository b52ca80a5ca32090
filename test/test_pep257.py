# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Docstrings as ROS 2 Jazzy's ament_pep257 checks them.

Its "ament" convention, less the D-codes the house style in setup.cfg [flake8] ignores (flake8's
docstring plugin and ament_pep257 both run pydocstyle), so the style is stated once.
"""
import configparser
from pathlib import Path

import pytest
from ament_pep257.main import main

ROOT = Path(__file__).resolve().parents[1]


def house_ignores():
    config = configparser.ConfigParser()
    config.read(ROOT / "setup.cfg")
    codes = config["flake8"]["extend-ignore"].replace("\n", "").split(",")
    return [c.strip() for c in codes if c.strip().startswith("D")]


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257(monkeypatch):
    monkeypatch.chdir(ROOT)
    ignores = house_ignores()
    assert "D401" in ignores and "D204" not in ignores
    rc = main(argv=[".", "--add-ignore", *ignores, "--exclude", "build", "install", "log"])
    assert rc == 0, "Found code style errors / warnings"


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257_reports_a_breach(tmp_path, capsys):
    bad = tmp_path / "bad.py"
    bad.write_text('class A:\n    """A class."""\n    x = 1\n')  # D204: no blank line after
    assert main(argv=[str(bad), "--add-ignore", *house_ignores()]) == 1
    assert "D204: 1 blank line required after class docstring" in capsys.readouterr().err
