# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The rules of the house: no import circle, small files, and every published figure backed by a
committed benchmark output (docs/results/)."""
import ast
import csv
import json
import re
from pathlib import Path

from conftest import load_benchmark

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("active_recognition", "msg_adapters")
MAX_LINES = 400


def module_name(path, root):
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph(root, packages=PACKAGES):
    """{module: set of the package modules it imports}, every import in the file counted (a
    lazy import inside a function closes a circle as surely as one at the top)."""
    files = {module_name(p, root): p for pkg in packages for p in (root / pkg).rglob("*.py")}
    graph = {}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        edges = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = package.split(".")
                base = base[:len(base) - node.level + 1] if node.level else []
                mod = ".".join(base + ([node.module] if node.module else []))
                targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in files else mod
                           for a in node.names]
            else:
                continue
            edges.update(t for t in targets if t in files and t != name)
        graph[name] = edges
    return graph


def cycles(graph):
    """Each import circle once, as a list of modules (Tarjan's strongly connected components)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_cycle_finder_sees_a_lazy_circle(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .b import f\n")
    (pkg / "b.py").write_text("def f():\n    from . import a\n")
    (pkg / "c.py").write_text("from pkg.a import f\n")
    graph = import_graph(tmp_path, ("pkg",))
    assert graph["pkg.c"] == {"pkg.a"}
    assert cycles(graph) == [["pkg.a", "pkg.b"]]


def test_no_import_circle():
    graph = import_graph(ROOT)
    assert "active_recognition.evaluation.evaluate" in graph and graph["active_recognition.training.train"]
    assert cycles(graph) == []


def test_no_module_over_400_lines():
    files = [p for folder in (*PACKAGES, "benchmarks") for p in (ROOT / folder).rglob("*.py")]
    assert any(p.parts[-2] == "benchmarks" for p in files) and any(p.parts[-2] == "msg_adapters" for p in files)
    long = {str(p.relative_to(ROOT)): n for p in files if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert long == {}, f"over {MAX_LINES} lines (two jobs in one file?): {long}"


def test_the_core_never_imports_rclpy():
    graph_files = [p for p in (ROOT / "active_recognition").rglob("*.py") if "nodes" not in p.parts]
    users = [str(p.relative_to(ROOT)) for p in graph_files if re.search(
        r"^\s*(import|from) rclpy", p.read_text(), re.M)]
    assert users == []


def test_results_page_is_what_the_committed_output_renders(tmp_path):
    load_benchmark("results_page").write_results_page(tmp_path / "RESULTS.md", ROOT / "docs/results")
    assert (tmp_path / "RESULTS.md").read_text() == (ROOT / "docs/RESULTS.md").read_text(), \
        "docs/RESULTS.md is stale: python benchmarks/results_page.py"


# A figure: a number followed by % or points, or any number with a decimal point, in the prose
# and tables of a page (not in code, where settings and commands are written, and not after a
# <!-- marker -->, whose figure a test of its own measures).
FIGURE = re.compile(r"(?<![\w.])(?<![A-Za-z]-)([-+]?\d+(?:,\d{3})*(?:\.\d+)?)(?=\s?%|\s(?:points?)\b)"
                    r"|(?<![\w.])(?<![A-Za-z]-)([-+]?\d+\.\d+)(?![\w.])")
SOURCE = re.compile(r"docs/results/[\w./-]+\.(?:json|csv)")
SETTINGS = {"24.04"}  # Ubuntu's release, not a measurement


def prose(block):
    block = re.sub(r"`[^`\n]*`", "", block)
    return re.sub(r"<!--.*?-->\s*\S+", "", block)


def blocks(text):
    """The page's paragraphs and tables, code blocks left out."""
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    return [b for b in re.split(r"\n\s*\n", text) if b.strip()]


def file_numbers(path):
    """Every number in a committed JSON or CSV output."""
    if path.suffix == ".json":
        def walk(obj):
            if isinstance(obj, dict):
                obj = list(obj.values())
            if isinstance(obj, list):
                return [x for o in obj for x in walk(o)]
            return [] if isinstance(obj, bool) or not isinstance(obj, (int, float)) else [obj]
        return walk(json.loads(path.read_text()))
    values = []
    for row in csv.reader(path.open()):
        for cell in row:
            try:
                values.append(float(cell))
            except ValueError:
                pass
    return values


def written_as(token, values):
    """Whether `token` (as printed) is one of `values`, as a fraction or in per cent, rounded to
    the token's decimals; the sign is the prose's own."""
    token = token.lstrip("+-").replace(",", "")
    decimals = len(token.partition(".")[2])
    return any(f"{abs(x):.{decimals}f}" == token for v in values for x in (v, 100 * v))


def unbacked(text, root=ROOT):
    """(figure, why) for every figure of a page that its paragraph's sources do not hold. A
    paragraph names its sources (docs/results/....json or .csv); a table takes those of the
    paragraph before it too."""
    problems, previous = [], []
    for block in blocks(text):
        table = block.lstrip().startswith("|")
        sources = list(dict.fromkeys(SOURCE.findall(block) + (previous if table else [])))
        previous = SOURCE.findall(block)
        values = [v for s in sources if (root / s).is_file() for v in file_numbers(root / s)]
        for m in FIGURE.finditer(prose(block)):
            token = m.group(1) or m.group(2)
            if token in SETTINGS:
                continue
            if not sources:
                problems.append((token, f"no docs/results source named near: {block[:70]!r}"))
            elif not written_as(token, values):
                problems.append((token, f"not in {', '.join(sources)}"))
    return problems


def test_the_figure_check_catches_a_figure_without_its_output(tmp_path):
    (tmp_path / "docs/results").mkdir(parents=True)
    (tmp_path / "docs/results/a.json").write_text(json.dumps({"acc": {"x": 0.8812}, "n": 500}))
    page = ("Scores 88.1 % on 500 objects (docs/results/a.json).\n\n"
            "| planner | acc |\n|---|---|\n| x | 88.1 |\n\n"
            "It scored 77.0 % once.\n\nA setting in code: `radius 1.5`.\n\n"
            "Stale: 88.2 % (docs/results/a.json).\n\nGone: 12.5 points (docs/results/gone.json).\n")
    assert unbacked(page, tmp_path) == [
        ("77.0", "no docs/results source named near: 'It scored 77.0 % once.'"),
        ("88.2", "not in docs/results/a.json"),
        ("12.5", "not in docs/results/gone.json")]


# Pages written from code, not by hand: RESULTS.md is rendered from docs/results/ itself (the
# test above keeps it current), options.md from the options' dataclasses (settings, not figures).
GENERATED = {"RESULTS.md", "options.md"}


TRIES = ROOT / "docs/results/tries.md"  # what was tried and not shipped, with its figures


def pages():
    """The hand-written pages: the README, docs/*.md but the generated ones, and the tries."""
    return ([ROOT / "README.md"] + [p for p in sorted((ROOT / "docs").glob("*.md")) if p.name not in GENERATED]
            + [TRIES])


def test_every_figure_of_the_readme_and_docs_comes_from_a_committed_output():
    names = {p.name for p in pages()}
    assert {"README.md", "ros.md", "training.md", "datasets.md", "benchmarks.md", "tries.md"} <= names, names
    problems = [(p.relative_to(ROOT), t, why) for p in pages() for t, why in unbacked(p.read_text())]
    assert problems == [], "figures without a committed output behind them:\n" + "\n".join(
        f"  {page}: {t}: {why}" for page, t, why in problems)


ISSUE = re.compile(r"#\d+\b|\bissues? \d+|before_\d+\b(?!\.yaml)")


def test_no_page_names_an_issue():
    """History lives in git: the pages, and the template of RESULTS, name no issue number (a config
    file whose name has one may be named as a file)."""
    texts = {p.relative_to(ROOT): p.read_text() for p in pages() + [ROOT / "docs/RESULTS.md",
                                                                    ROOT / "benchmarks/results_template.md"]}
    found = {str(page): ISSUE.findall(text) for page, text in texts.items() if ISSUE.search(text)}
    assert found == {}


def test_the_readme_stays_short():
    assert len((ROOT / "README.md").read_text().splitlines()) <= 200, "move the detail to docs/"


def test_the_docs_count_the_held_out_styles_as_the_code_does():
    from active_recognition.datasets import furniture

    held = sum(len(furniture.styles(name, True)) for name in furniture.FACTORS)
    every = held + sum(len(furniture.styles(name, False)) for name in furniture.FACTORS)
    text = " ".join((ROOT / "docs/datasets.md").read_text().split())
    assert f"Some combinations of every class ({held} of {every}) are held out" in text


def test_the_recognizer_node_is_a_thin_shell():
    """The rclpy shell (the node, its outputs, its action server) stays small: the loop lives in
    controller.py, without ROS. 477 lines: its size before its state was made explicit."""
    nodes = ROOT / "active_recognition" / "nodes"
    lines = sum(len(p.read_text().splitlines()) for p in (*nodes.glob("recognizer*.py"), nodes / "recognize_server.py"))
    assert 0 < lines <= 477, lines


def imported_modules(path):
    """The top-level names of every module a file imports (lazy imports too)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level:
            names.add(node.module.split(".")[0])
    return names


def test_only_the_nodes_import_rclpy():
    offenders = [str(p.relative_to(ROOT)) for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")
                 if "nodes" not in p.relative_to(ROOT).parts and "rclpy" in imported_modules(p)]
    assert offenders == []


def test_the_runtime_imports_nothing_of_the_harness():
    """What the nodes import, directly or through others, holds no training or evaluation."""
    graph = import_graph(ROOT)
    runtime = [m for m in graph if m.startswith("active_recognition.nodes.") and m != "active_recognition.nodes.demo"]
    seen, todo = set(), list(runtime)
    while todo:
        module = todo.pop()
        if module not in seen:
            seen.add(module)
            todo.extend(graph[module])
    harness = {f"active_recognition.{m}" for m in ("training.train", "evaluation.evaluate", "unknown.fit")}
    assert "active_recognition.nodes.recognizer" in seen and seen & harness == set()


# A commit named by its hash: 7 to 40 hex digits with a letter and a digit among them, standing
# alone or in a file name (`model_1a2b3c4.pt`). Pins of other repositories' data, which a
# download needs, are not the project's history.
COMMIT = re.compile(r"(?<![0-9A-Za-z])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![0-9A-Za-z])")
PINS = {"eef81ff76641d63e9e50f227a925c6be3b178716"}  # datasets.md: the ModelNet10 copy's commit


def test_the_commit_finder_sees_a_hash_and_not_a_word():
    found = COMMIT.findall("git show 77bcafd:a.pt, modelnet10_aea09c4.pt, 1308b0b's loop; "
                           "decade, 1234567, deadbeef, 0x1f2e3d4c5b, v0.1.2, sha256 " + "ab12" * 10)
    assert found == ["77bcafd", "aea09c4", "1308b0b", "ab12" * 10]


def test_the_manuals_name_no_commit():
    """History lives in git and in the tries page: the README and docs/*.md name no commit (but
    RESULTS.md, rendered from the committed output, whose row labels may name a model by the
    commit that shipped it, and a pin in PINS)."""
    texts = {p.relative_to(ROOT): p.read_text() for p in pages() + [ROOT / "docs/options.md"] if p != TRIES}
    assert Path("docs/training.md") in texts
    found = {str(page): hashes for page, text in texts.items()
             if (hashes := [h for h in COMMIT.findall(text) if h not in PINS])}
    assert found == {}, f"name the committed output or the model, not the commit: {found}"


def test_the_results_page_links_the_tries():
    assert TRIES.is_file()
    assert "(results/tries.md)" in (ROOT / "docs/RESULTS.md").read_text()
