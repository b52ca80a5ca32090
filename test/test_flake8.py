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
