# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Licence headers, in the SPDX form (ament_copyright has no wheel and does not run here).

Every Python file and shell script opens (after a shebang) with two comment lines, a
`Copyright YEAR NAME` line and `SPDX-License-Identifier: Apache-2.0`; a Python file then has
its own docstring, so the first thing a reader (or a tool showing a file's opening) meets is what
the file is for. LICENSE holds the full licence text, and package.xml and setup.py declare the
same licence. YAML, XML and Markdown files carry no header: LICENSE covers the whole package.
"""
import ast
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SPDX = "SPDX-License-Identifier: Apache-2.0"
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
    """None when `path` opens with a copyright line, the SPDX line and (Python) a docstring, else
    the reason."""
    text = Path(path).read_text(encoding="utf-8")
    lines = text.splitlines()
    if lines and lines[0].startswith("#!"):
        lines = lines[1:]
    if not lines or not lines[0].startswith("# "):
        return "no comment block at the top"
    if not COPYRIGHT.fullmatch(lines[0][2:]):
        return f"first comment line is not 'Copyright YEAR NAME': {lines[0]!r}"
    if len(lines) < 2 or lines[1] != "# " + SPDX:
        return f"second line is not '# {SPDX}'"
    block = [line for line in lines[2:12] if line.startswith("#")]
    if any("Licensed under" in line for line in block):
        return "the old Apache notice follows the SPDX line"
    if Path(path).suffix == ".py" and text.strip() and ast.get_docstring(ast.parse(text)) is None:
        return "no module docstring after the header"
    return None


@pytest.mark.copyright
@pytest.mark.linter
def test_every_source_file_has_the_spdx_header():
    checked = list(sources(ROOT))
    assert any(p.name == "setup.py" for p in checked) and any(p.name == "run" for p in checked)
    problems = [f"{p.relative_to(ROOT)}: {why}" for p in checked if (why := header_problem(p))]
    assert not problems, "files without the licence header:\n" + "\n".join(problems)


@pytest.mark.parametrize("text,reason", [
    ('"""No header."""\n', "no comment block"),
    ("# Copyright someone\n# " + SPDX + "\n", "Copyright YEAR NAME"),
    ("# Copyright 2026 someone\n# SPDX-License-Identifier: MIT\n", "second line"),
    ("# Copyright 2026 someone\n# " + SPDX + "\n#\n# Licensed under the Apache License\n",
     "old Apache notice"),
    ("# Copyright 2026 someone\n# " + SPDX + "\n\nimport os\n", "no module docstring"),
])
def test_a_missing_or_wrong_header_is_named(tmp_path, text, reason):
    path = tmp_path / "bad.py"
    path.write_text(text)
    assert reason in header_problem(path)
    good = tmp_path / "good.py"
    good.write_text("#!/usr/bin/env python3\n# Copyright 2026 someone\n# " + SPDX
                    + '\n\n"""What it is for."""\nimport os\n')
    assert header_problem(good) is None
    script = tmp_path / "run.sh"
    script.write_text("#!/usr/bin/env bash\n# Copyright 2026 someone\n# " + SPDX + "\nset -e\n")
    assert header_problem(script) is None


def test_license_file_and_declarations_agree():
    text = (ROOT / "LICENSE").read_text()
    assert "Apache License\n                           Version 2.0, January 2004" in text
    assert "END OF TERMS AND CONDITIONS" in text and "APPENDIX: How to apply" in text
    package = ET.parse(ROOT / "package.xml").getroot()
    assert [e.text for e in package.findall("license")] == ["Apache-2.0"]
    assert 'license="Apache-2.0"' in (ROOT / "setup.py").read_text()
