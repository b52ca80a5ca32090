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

"""Licence headers, checked as ament_copyright checks them (it has no wheel, so this stands in).

Every Python file and shell script opens (after a shebang) with a comment block holding a
`Copyright YEAR NAME` line and the Apache-2.0 notice; LICENSE holds the full licence text, and
package.xml and setup.py declare the same licence. YAML, XML and Markdown files carry no header:
ament_copyright does not check them either, and LICENSE covers the whole package.
"""
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTICE = """Licensed under the Apache License, Version 2.0 (the "License");
you may not use this file except in compliance with the License.
You may obtain a copy of the License at

    http://www.apache.org/licenses/LICENSE-2.0

Unless required by applicable law or agreed to in writing, software
distributed under the License is distributed on an "AS IS" BASIS,
WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
See the License for the specific language governing permissions and
limitations under the License."""
COPYRIGHT = re.compile(r"Copyright (\d{4})(-\d{4})? \S.*")
SKIP_DIRS = {"build", "install", "log", "runs"}  # colcon's workspace folders, training output


def sources(root):
    """Python files and shell scripts under `root`, skipping hidden folders as ament does (but
    not .ci, the CI script's)."""
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d == ".ci" or (d[0] not in "._" and d not in SKIP_DIRS)]
        for name in files:
            path = Path(folder, name)
            if path.suffix in (".py", ".sh") or (not path.suffix and shell_script(path)):
                yield path


def shell_script(path):
    with open(path, "rb") as f:
        first = f.readline()
    return first.startswith(b"#!") and first.rstrip().split(b"/")[-1].split()[-1] in (b"sh", b"bash")


def header_problem(path):
    """None when `path` opens with a copyright line and the Apache-2.0 notice, else the reason."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    if lines and lines[0].startswith("#!"):
        lines = lines[1:]
    block = []
    for line in lines:
        if not line.startswith("#"):
            break
        block.append(line[2:] if line.startswith("# ") else line[1:])
    if not block:
        return "no comment block at the top"
    if not COPYRIGHT.fullmatch(block[0]):
        return f"first comment line is not 'Copyright YEAR NAME': {block[0]!r}"
    if "\n".join(block[1:]).strip() != NOTICE:
        return "the comment block after the copyright line is not the Apache-2.0 notice"
    return None


@pytest.mark.copyright
@pytest.mark.linter
def test_every_source_file_has_the_apache_header():
    checked = list(sources(ROOT))
    assert any(p.name == "setup.py" for p in checked) and any(p.name == "run" for p in checked)
    problems = [f"{p.relative_to(ROOT)}: {why}" for p in checked if (why := header_problem(p))]
    assert not problems, "files without the licence header:\n" + "\n".join(problems)


@pytest.mark.parametrize("text,reason", [
    ('"""No header."""\n', "no comment block"),
    ("# Copyright someone\n#\n# " + NOTICE.replace("\n", "\n# ") + "\n", "Copyright YEAR NAME"),
    ("# Copyright 2026 someone\n#\n# Licensed under the MIT License.\n", "not the Apache-2.0"),
])
def test_a_missing_or_wrong_header_is_named(tmp_path, text, reason):
    path = tmp_path / "bad.py"
    path.write_text(text)
    assert reason in header_problem(path)
    good = tmp_path / "good.py"
    good.write_text("#!/usr/bin/env python3\n# Copyright 2026 someone\n#\n# "
                    + NOTICE.replace("\n", "\n# ").replace("# \n", "#\n") + "\nimport os\n")
    assert header_problem(good) is None


def test_license_file_and_declarations_agree():
    text = (ROOT / "LICENSE").read_text()
    assert "Apache License\n                           Version 2.0, January 2004" in text
    assert "END OF TERMS AND CONDITIONS" in text and "APPENDIX: How to apply" in text
    package = ET.parse(ROOT / "package.xml").getroot()
    assert [e.text for e in package.findall("license")] == ["Apache-2.0"]
    assert 'license="Apache-2.0"' in (ROOT / "setup.py").read_text()
