# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Writes docs/RESULTS.md: the prose of benchmarks/results_template.md with its tables filled in
from the benchmarks' committed output under docs/results/.

Every figure on the page comes from those files (the summaries of benchmarks/planners.py, the
JSON of dataset_difficulty.py, camera_robustness.py, old_vs_new.py and runs_table.py); the
template adds the commands that made them and what each table shows, nothing measured of its
own. The template is cut into sections by `<!-- section NAME -->` lines; BUILDERS[NAME] reads
the output the section shows and gives the values of its `{{placeholders}}`, or None where that
output is missing, which leaves the section out.

    python benchmarks/results_page.py [--results docs/results] [--out docs/RESULTS.md]
"""
import argparse
import csv
import json
import re
from pathlib import Path

from results_robot import camera_parts, load, pct, real_unknowns, robot_seconds

from active_recognition.atomic_files import write_text
from active_recognition.evaluation.report import PAPER, PAPER_MODELNET10, PAPER_TRAINING_HOURS, table

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = Path(__file__).with_name("results_template.md")
SECTION = re.compile(r"^<!-- section (\w+) -->\n", re.M)
PLACEHOLDER = re.compile(r"\{\{(\w+)\}\}")


def sections():
    """{name: text} of the template's sections, in the page's order."""
    pieces = SECTION.split(TEMPLATE.read_text())[1:]
    return {name: body.strip("\n") for name, body in zip(pieces[::2], pieces[1::2])}


def fill(name, values, template=None):
    """Section `name` of the template, its placeholders replaced by `values` ('' for None)."""
    if values is None:
        return ""
    body = (template or sections())[name]
    missing = sorted(set(PLACEHOLDER.findall(body)) - set(values))
    if missing:
        raise KeyError(f"{TEMPLATE.name}, section {name}: no value for {', '.join(missing)}")
    return PLACEHOLDER.sub(lambda m: str(values[m.group(1)]), body)


def page_text(results):
    """The whole page for the output under `results` (summary.json, procedural's, is required)."""
    template = sections()
    if set(template) != set(BUILDERS):
        raise KeyError(f"{TEMPLATE.name} and BUILDERS differ in: {sorted(set(template) ^ set(BUILDERS))}")
    parts = [fill(name, BUILDERS[name](Path(results)), template) for name in template]
    return "\n\n".join(p for p in parts if p) + "\n"


def write_results_page(path, results):
    """docs/RESULTS.md from the summaries under `results`, beside the paper's figures."""
    write_text(path, page_text(results))


def summary(results):
    """The procedural benchmark's planners.py output, which every page has."""
    return json.loads((Path(results) / "summary.json").read_text())


def shared(s):
    """The shared classifier's table of a summary that has one."""
    return {"table": accuracy_table(s, "acc_shared", "stderr_3_shared")} if "acc_shared" in s else None


def accuracy_rows(s, key, err):
    """Table rows of a summary's accuracies (%) at 3 / 6 / 9 views, with the standard error at 3
    when the summary has it."""
    return [[k] + [pct(v) for v in s[key][k].values()]
            + ([pct(s[err][k])] if err in s else []) for k in s[key]]


def accuracy_table(s, key="acc", err="stderr_3", extra=()):
    """accuracy_rows as a table, `extra` rows (of the paper) under them."""
    rows = accuracy_rows(s, key, err)
    return table(rows + list(extra), ["planner", "3", "6", "9"] + (["s.e. at 3"] if err in s else []))


def episodes(folder):
    """How many objects and starts an evaluation ran, from its per_object.csv."""
    path = Path(folder) / "per_object.csv"
    if not path.is_file():
        return "episodes as in its command"
    with open(path) as f:
        rows = list(csv.DictReader(f))
    first = rows[0]["planner"] if rows else ""
    mine = [r for r in rows if r["planner"] == first]
    objects = len({r["object"] for r in mine})
    starts = len(mine) // max(objects, 1)
    return (f"{objects} test objects, {starts} seeded initial view(s) each of the 50, the same "
            f"for every planner: {len(mine):,} episodes")


def paper_ratio():
    """The paper's training-time ratio, end to end over REINFORCE, as a sentence."""
    ours = PAPER_TRAINING_HOURS["end-to-end (ours in the paper)"]
    theirs = PAPER_TRAINING_HOURS["MV-RNN (REINFORCE)"]
    return f"{ours} h / {theirs:g} h = {ours / theirs:.2f}"


def seconds(value):
    return "never" if value is None else f"{value:.0f} s"


def ratio(t):
    return "n/a" if t.get("ratio") is None else f"{t['ratio']:.2f}"


def headroom(path):
    """The room a planner has, from benchmarks/dataset_difficulty.py's JSON."""
    d = load(path)
    if d is None:
        return None
    keys = ("acc_1_view", "acc_3_random", "acc_3_best", "acc_3_best_fixed", "acc_9_views")
    return {"table": table([[pct(d[k]) for k in keys]],
                           ["1 random view", "3 random", "best 3 of 50 (privileged)",
                            "random + best fixed 2", "9 spread"]),
            "best_minus_random": pct(d["acc_3_best"] - d["acc_3_random"], "+.1f"),
            "best_minus_fixed": pct(d["acc_3_best"] - d["acc_3_best_fixed"], "+.1f")}


def study(path):
    """A table of runs (learned / random / straight at k views) from docs/results/<study>.json."""
    data = load(path)
    if data is None:
        return None
    k = data["views"]
    rows = [[label] + [pct(acc[p][k - 1]) for p in ("learned", "random", "straight")]
            + [pct(acc["learned"][k - 1] - max(acc["random"][k - 1], acc["straight"][k - 1]), "+.1f")]
            for label, acc in data["acc"].items()]
    header = ["run", "own view head", "random", "straight", "own head - best baseline"]
    return {"views": k, "table": table(rows, header)}


def procedural_more(results):
    """Information gain, the early stop, training time and the paper's figures."""
    s = summary(results)
    t = s.get("training_time", {})
    steps = len(next(iter(s["gain"].values())))
    return {
        "gain": table([[k] + [f"{g:.3f}" for g in v] for k, v in s["gain"].items()],
                      ["planner"] + [str(i + 1) for i in range(steps)]),
        "threshold": s.get("entropy_threshold", 0.1),
        "early_stop": table([[k, pct(v["accuracy"]), f"{v['mean_views']:.2f}"]
                             for k, v in s["early_stop"].items()], ["planner", "accuracy %", "mean views"]),
        "reinforce_best": pct(t.get("reinforce_best", float("nan"))),
        "learned_s": seconds(t.get("learned_s")), "reinforce_s": seconds(t.get("reinforce_s")),
        "ratio": ratio(t), "paper_ratio": paper_ratio(),
        "learned_best": pct(t.get("learned_best", float("nan"))),
        "learned_s_to_learned_best": seconds(t.get("learned_s_to_learned_best")),
        "reinforce_s_to_learned_best": seconds(t.get("reinforce_s_to_learned_best")),
        "paper": table([[k, a, b, c] for k, (a, b, c) in PAPER.items()], ["dataset", "3", "6", "9"]),
        "paper_hours": ", ".join(f"{k} {v}" for k, v in PAPER_TRAINING_HOURS.items())}


def cross(results):
    """Every planner on the held-out styles (`planners.py --split cross`) beside the test split."""
    c, in_style = load(results / "procedural-cross" / "summary.json"), summary(results)
    if c is None:
        return None
    rows = [row + [pct(c["acc"][row[0]]["3"] - in_style["acc"][row[0]]["3"], "+.1f")]
            for row in accuracy_rows(c, "acc", "stderr_3") if row[0] in in_style["acc"]]
    return {"episodes": episodes(results / "procedural-cross"),
            "table": table(rows, ["planner", "3", "6", "9", "s.e. at 3", "vs test split at 3"])}


def old_vs_new(results):
    """The shipped model before and after the furniture-like generator (benchmarks/old_vs_new.py)."""
    d = load(results / "old_vs_new.json")
    if d is None:
        return None
    splits = list(dict.fromkeys(k.split(", ")[1] for k in d))
    models = list(dict.fromkeys(k.split(" model, ")[0] for k in d))
    rows = [[f"{m} model, {p}"] + [pct(d[f"{m} model, {sp}, {p}"]) for sp in splits]
            for m in models for p in ("learned", "straight")]
    return {"table": table(rows, ["model, planner"] + splits)}


def camera_table(d):
    """The rows of benchmarks/camera_robustness.py's JSON, each against the clean camera."""
    clean = d["rows"]["clean"]["acc_3"]

    def target(name):  # points below clean allowed: the held-out styles 5, any other row 3
        return 5 if name.startswith("cross-style") else 3

    rows = [[name, pct(r["acc_3"]), pct(r["acc_3"] - clean, "+.1f"),
             "" if name == "clean" else f"-{target(name)}: "
             + ("met" if 100 * (clean - r["acc_3"]) <= target(name) else "missed"),
             pct(r["acc_stop"]), f"{r['mean_views']:.2f}"] for name, r in d["rows"].items()]
    return table(rows, ["camera", "acc. after 3 views %", "vs clean", "target", "acc. at stop %",
                        "mean views"])


def camera(results):
    d = load(results / "camera_robustness.json")
    if d is None:
        return None
    return {"model": Path(d["checkpoint"]).name, "objects": d["objects"],
            "stderr": pct(d["rows"]["clean"]["stderr_3"]), "table": camera_table(d)}


def camera_closest(results):
    """The rows re-run on more objects, where the first table's standard error was too wide."""
    small, big = load(results / "camera_robustness.json"), load(results / "camera_robustness_500.json")
    if small is None or big is None:
        return None
    return {"objects": big["objects"], "small_objects": small["objects"],
            "stderr": pct(small["rows"]["clean"]["stderr_3"]), "table": camera_table(big)}


def modelnet(results):
    """ModelNet10, the paper's benchmark: every planner beside the paper's Table 3."""
    s = load(results / "modelnet10" / "summary.json")
    if s is None:
        return None
    paper = [[f"{k} (paper)", *v] + ([""] if "stderr_3" in s else []) for k, v in PAPER_MODELNET10.items()]
    return {"episodes": episodes(results / "modelnet10"), "table": accuracy_table(s, extra=paper)}


def size_prior(results):
    """What the object's size adds (modelnet10.pt's size prior), chosen on the validation split."""
    c = load(results / "modelnet10" / "size_prior.json")
    if c is None:
        return None
    base = c["grid"]["weight 0.0 outlier 0.01"]
    best = c["grid"][f"weight {c['chosen']['weight']} outlier {c['chosen']['outlier']}"]
    return {"weight": c["chosen"]["weight"], "outlier": c["chosen"]["outlier"],
            "objects": c["objects"], "starts": c["starts"], "planners": ", ".join(base["acc"]),
            "before": pct(base["mean"], ".2f"), "after": pct(best["mean"], ".2f")}


def size_prior_reinforce(results):
    """The REINFORCE row's model carries a prior of its own, chosen the same way."""
    r = load(results / "modelnet10" / "size_prior_reinforce.json")
    return None if r is None else {"weight": r["chosen"]["weight"], "outlier": r["chosen"]["outlier"]}


def size_prior_none(results):
    """Said where modelnet10.pt has a prior and the REINFORCE row's model has none."""
    folder = results / "modelnet10"
    return {} if (folder / "size_prior.json").is_file() and not (
        folder / "size_prior_reinforce.json").is_file() else None


def images_only(results):
    """modelnet10.pt answering from the images alone (`planners.py --no-size`), beside its prior."""
    a = load(results / "modelnet10" / "images_only" / "summary.json")
    has_prior = (results / "modelnet10" / "size_prior.json").is_file()
    return {"table": accuracy_table(a)} if a is not None and has_prior else None


def modelnet_summary(results, keys, build):
    """build(summary) where ModelNet10's summary has every one of `keys`, else None."""
    s = load(results / "modelnet10" / "summary.json")
    return build(s) if s is not None and all(s.get(k) for k in keys) else None


def per_class(s):
    names = list(s["per_class_3"])
    rows = [[c] + [pct(s["per_class_3"][n][i]) for n in names] for i, c in enumerate(s["classes"])]
    return {"table": table(rows, ["class"] + names)}


def twins(results, build):
    """build(twins summary, folder) where twins/summary.json was written, else None."""
    s = load(results / "twins" / "summary.json")
    return None if s is None else build(s, results / "twins")


def leads(s, best, over):
    """How far `best` leads the best of `over` at 3 views, with its own and the shared classifier."""
    own, sh = ({k: v["3"] for k, v in s[key].items()} for key in ("acc", "acc_shared"))
    return {"planner": best, "lead": pct(own[best] - max(own[p] for p in over), "+.1f"),
            "lead_shared": pct(sh[best] - max(sh[p] for p in over), "+.1f")}


def twins_lead(s, over):
    """The default planner's lead over the best of `over` (where random and straight ran too)."""
    best = s.get("default_planner")
    if not best or any(p not in s["acc"] for p in ("random", "straight", *over)):
        return None
    return leads(s, best, over)


def twins_learned_lead(s, _):
    if "learned" not in s["acc"] or twins_lead(s, ("random", "straight")) is None:
        return None
    return {"lead": pct(s["acc"]["learned"]["3"] - s["acc"]["straight"]["3"], "+.1f")}


def turned(s, folder, yaw=45):
    """The benchmark with every object turned by its own yaw within +-`yaw` degrees
    (`planners.py --yaw 45`; 180: the heading unknown)."""
    turn = folder.parent / f"{folder.name}-yaw{yaw:g}"
    t = load(turn / "summary.json")
    if t is None:
        return None
    return {"dataset": turn.name.split("-")[0], "episodes": episodes(turn),
            "summary": f"{turn.relative_to(turn.parents[2])}/summary.json",
            "own": accuracy_table(t), "shared": accuracy_table(t, "acc_shared", "stderr_3_shared")}


def turned_lead(s, folder, yaw=45):
    """The default planner's lead with the heading turned, and what the turn costs it."""
    t, best = load(folder.parent / f"{folder.name}-yaw{yaw:g}" / "summary.json"), s.get("default_planner")
    fixed = [p for p in ("random", "straight", "fixed") if t is not None and p in t["acc"]]
    if not fixed or best not in t["acc"]:
        return None
    return {**leads(t, best, fixed), "fixed": ", ".join(fixed),
            "drop": pct(s["acc"][best]["3"] - t["acc"][best]["3"])}


def adaptive_lead(s, folder, yaw):
    """Turned: the 3-view cost to fixed, imitation, learned and the default; imitation's lead."""
    t, best = load(folder.parent / f"{folder.name}-yaw{yaw:g}" / "summary.json"), s.get("default_planner")
    if t is None or any(p not in t["acc"] for p in ("fixed", "imitation", "learned", best)):
        return None
    names = ("fixed", "imitation", "learned")
    return {**{f"{p}_change": pct(t["acc"][p]["3"] - s["acc"][p]["3"], "+.1f") for p in names},
            **{k: pct(t[key]["imitation"]["3"] - t[key]["fixed"]["3"], "+.1f")
               for k, key in (("lead", "acc"), ("lead_shared", "acc_shared"))},
            "planner": best, "change": pct(t["acc"][best]["3"] - s["acc"][best]["3"], "+.1f")}


def twins_training_time(s, _):
    t = s.get("training_time", {})
    if not t:
        return None
    return {"reinforce_best": pct(t["reinforce_best"]), "reinforce_s": f"{t.get('reinforce_s') or 0:.0f}",
            "learned": ("never reaches it" if t.get("learned_s") is None
                        else f"reaches it in {t['learned_s']:.0f} s"),
            "learned_best": pct(t["learned_best"]), "ratio": ratio(t), "paper_ratio": paper_ratio()}


# section of results_template.md -> its values from the results folder (None: leave it out)
BUILDERS = {
    "procedural": lambda r: summary(r) and {"episodes": episodes(r)},  # summary.json is required
    "procedural_headroom": lambda r: headroom(r / "difficulty.json"),
    "procedural_own": lambda r: {"table": accuracy_table(summary(r))},
    "procedural_shared": lambda r: shared(summary(r)),
    "procedural_cross": cross,
    "procedural_more": procedural_more,
    "view_head": lambda r: study(r / "view_head.json"),
    "ablations": lambda r: study(r / "ablations.json"),
    "old_vs_new": old_vs_new,
    "camera": camera,
    "camera_closest": camera_closest,
    "modelnet": modelnet,
    "modelnet_size": size_prior,
    "modelnet_size_reinforce": size_prior_reinforce,
    "modelnet_size_none": size_prior_none,
    "modelnet_images_only": images_only,
    "modelnet_shared": lambda r: modelnet_summary(r, ("acc_shared",), shared),
    "modelnet_default": lambda r: modelnet_summary(r, ("default_planner",),
                                                   lambda s: {"planner": s["default_planner"]}),
    "modelnet_per_class": lambda r: modelnet_summary(r, ("per_class_3", "classes"), per_class),
    "modelnet_seconds": robot_seconds,
    "modelnet_camera": camera_parts,
    "modelnet_real_unknowns": real_unknowns,
    "modelnet_yaw": lambda r: modelnet_summary(r, (), lambda s: turned(s, r / "modelnet10", 180)),
    "modelnet_yaw_lead": lambda r: modelnet_summary(r, (), lambda s: adaptive_lead(s, r / "modelnet10", 180)),
    "twins": lambda r: twins(r, lambda s, folder: {"episodes": episodes(folder)}),
    "twins_headroom": lambda r: twins(r, lambda s, folder: headroom(folder / "difficulty.json")),
    "twins_tables": lambda r: twins(r, lambda s, folder: {"own": accuracy_table(s), "shared": shared(s)["table"]}),
    "twins_lead": lambda r: twins(r, lambda s, folder: twins_lead(s, ("random", "straight"))),
    "twins_lead_fixed": lambda r: twins(r, lambda s, folder: twins_lead(s, ("fixed",))),
    "twins_lead_learned": lambda r: twins(r, twins_learned_lead),
    "twins_yaw": lambda r: twins(r, turned),
    "twins_yaw_lead": lambda r: twins(r, turned_lead),
    "twins_training_time": lambda r: twins(r, twins_training_time),
    "twins_candidates": lambda r: study(r / "twins_candidates.json"),
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", default=ROOT / "docs/results", help="benchmark output folder")
    # --out by hand: a Markdown page, not a JSON file
    parser.add_argument("--out", default=ROOT / "docs/RESULTS.md", help="the page to write")
    args = parser.parse_args(argv)
    write_results_page(args.out, args.results)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
