# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What views cost a robot (robot_time.RobotTime), against sums done by hand, and the loop's
time_budget: it answers before the next view would overrun it."""
import math

import numpy as np
import pytest
from conftest import sure_or_not

from active_recognition.argument_checks import InputError
from active_recognition.model.checkpoint import shipped
from active_recognition.model.episode import EpisodeConfig
from active_recognition.runtime.active_recognizer import ActiveRecognizer
from active_recognition.runtime.controller import AskView, Controller, End, Timing
from active_recognition.runtime.controller_commands import Step
from active_recognition.runtime.robot_time import RobotTime
from active_recognition.simulation.depth_sensor import SimulatedCamera


def test_seconds_are_captures_settles_and_travel():
    cost = RobotTime(capture_s=0.1, settle_s=0.5, rad_per_s=0.5)
    quarter = [(math.pi / 2, 0.0), (math.pi / 2, math.pi / 2), (math.pi / 2, math.pi)]
    # 3 captures, 2 settles, two quarter turns (pi rad) at 0.5 rad/s
    assert cost.seconds(quarter) == pytest.approx(3 * 0.1 + 2 * 0.5 + math.pi / 0.5)
    assert cost.seconds(quarter[:1]) == pytest.approx(0.1) and cost.seconds(np.zeros((0, 2))) == 0.0
    rng = np.random.default_rng(3)
    views = np.stack([np.arccos(rng.uniform(-1, 1, 6)), rng.uniform(-np.pi, np.pi, 6)], -1)
    for n in range(6):  # one more view adds what next_view says
        more = cost.seconds(views[:n]) + cost.next_view(views[:n], views[n])
        assert cost.seconds(views[:n + 1]) == pytest.approx(more)


@pytest.mark.parametrize("bad", [dict(rad_per_s=0.0), dict(capture_s=-1.0), dict(settle_s=float("nan"))])
def test_a_bad_cost_model_is_refused(bad):
    with pytest.raises(InputError, match=next(iter(bad))):
        RobotTime(**bad)


@pytest.fixture(scope="module")
def camera():
    sim = SimulatedCamera(seed=0)
    sim.load(dataset="procedural", split="test", index=6)
    return sim


@pytest.mark.parametrize("budget", [0.05, 1.0, 4.0, 9.0])
def test_an_episode_answers_before_the_next_view_would_overrun_its_budget(camera, budget):
    core = ActiveRecognizer(str(shipped("procedural")))
    core.rng = np.random.default_rng(2)
    loop = Controller(core, Timing(pose_wait=0.05, budget_entropy_threshold=0.0))  # never sure: the budget stops it
    commands, now = loop.start(0.0, time_budget=budget), 0.0
    while not any(isinstance(c, End) for c in commands):
        ask = [c for c in commands if isinstance(c, AskView)][-1]
        now += 0.1
        metres, position, rotation = camera.capture(ask.position, ask.rotation)
        commands = loop.pose(now, ask.frame, ask.stamp, position, rotation) + loop.image(now, ask.stamp, metres)
    end = commands[-1]
    taken = core.views_taken()
    spent = loop.cost.seconds(taken)
    assert end.result["robot_seconds"] == pytest.approx(spent)
    assert end.result["status"] in (sure_or_not(end.result, core.confidence), "unknown")
    assert len(taken) >= 1 and (spent <= budget or len(taken) == 1)  # the first view is always taken
    if len(taken) < core.episode.config.max_views:  # stopped by the budget: one more would overrun
        assert spent + loop.cost.next_view(taken, core.view) > budget


def test_an_unreachable_view_is_not_replaced_by_one_the_budget_cannot_pay_for(camera):
    """After a view is given up, the one the planner picks in its place must fit the budget too:
    here none can (a move costs at least settle + capture, 0.6 s, and 0.55 s are left), so the
    episode answers with what it has instead of asking for it."""
    core = ActiveRecognizer(str(shipped("procedural")))
    core.rng = np.random.default_rng(2)
    loop = Controller(core, Timing(pose_wait=0.05, view_timeout=1.0, max_retries=0, budget_entropy_threshold=0.0))
    ask = loop.start(0.0, time_budget=30.0)[0]
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    commands = loop.pose(0.1, ask.frame, ask.stamp, position, rotation) + loop.image(0.1, ask.stamp, metres)
    assert any(isinstance(c, AskView) for c in commands) and len(core.views_taken()) == 1
    loop.budget = loop.cost.seconds(core.views_taken()) + 0.55
    ended = loop.tick(5.0)  # the second view never came (no resends): given up
    assert [type(c).__name__ for c in ended] == ["Refuse", "End"] and "time budget" in ended[0].reason
    assert ended[1].result["status"] == sure_or_not(ended[1].result, core.confidence) and ended[1].result["views"] == 1
    assert ended[1].result["robot_seconds"] <= loop.budget


def test_a_budget_brings_its_own_stop_rule_and_an_episode_without_one_the_nodes(camera):
    """With a time budget the episode stops at budget_entropy_threshold, without one at the
    node's entropy_threshold: each episode's stop is the one its start asked for."""
    # the node's entropy_threshold 1.0: this object takes 4 views (entropy 1.15 at the first)
    core = ActiveRecognizer(str(shipped("procedural")), EpisodeConfig(entropy_threshold=1.0))
    loop = Controller(core, Timing(pose_wait=0.05, budget_entropy_threshold=0.02))
    stops, views = [], []
    for budget in (30.0, 0.0, 30.0):
        commands, now = loop.start(0.0, time_budget=budget), 0.0
        stops.append(core.episode.config.entropy_threshold)
        entropies = []
        while not any(isinstance(c, End) for c in commands):
            ask = [c for c in commands if isinstance(c, AskView)][-1]
            now += 0.1
            metres, position, rotation = camera.capture(ask.position, ask.rotation)
            commands = loop.pose(now, ask.frame, ask.stamp, position, rotation) + loop.image(now, ask.stamp, metres)
            entropies += [c.obs.entropy for c in commands if isinstance(c, Step)]
        views.append(len(entropies))
        assert all(h >= stops[-1] for h in entropies[:-1])  # it went on while unsure
        taken = core.views_taken()
        assert entropies[-1] < stops[-1] or len(taken) == core.episode.config.max_views or \
            loop.cost.seconds(taken) + loop.cost.next_view(taken, core.view) > budget  # and stopped for a reason
    assert stops == [0.02, 1.0, 0.02] and views[1] < min(views[0], views[2])


def test_the_robot_seconds_benchmark_against_sums_by_hand(tmp_path):
    from conftest import load_benchmark

    bench = load_benchmark("robot_seconds")
    quarter = "1.5707963;0.0", "1.5707963;1.5707963", "1.5707963;3.1415927"
    header = ["planner", "object", "true", "start", "stopped_at", "early_stop_pred", "pred_1", "pred_2", "pred_3",
              "view_1", "view_2", "view_3"]
    rows = [["a", 0, "cup", 0, 3, "cup", "bowl", "cup", "cup", *quarter],   # right at its stop, wrong at 1 view
            ["a", 1, "cup", 0, 2, "bowl", "bowl", "bowl", "cup", *quarter]]  # wrong at its stop
    path = tmp_path / "per_object.csv"
    path.write_text("\n".join(",".join(map(str, r)) for r in [header, *rows]) + "\n")
    runs = bench.episodes(path)
    cost = RobotTime()
    f = bench.planner_figures(cost, runs["a"])
    assert f["travel_deg_3"] == pytest.approx(180.0, abs=1e-4) and f["stop_views"] == 2.5
    assert f["stop_accuracy"] == 0.5 and f["stop_accuracy_se"] == pytest.approx(0.5)  # std of (1, 0) / sqrt 2
    move = 0.5 + (math.pi / 2) / 0.5  # a settle and a quarter turn
    assert f["stop_seconds_mean"] == pytest.approx(((0.3 + 2 * move) + (0.2 + move)) / 2, abs=1e-5)
    # 4 s: the first view and one move (0.2 + 3.64 s) fit, a second does not: episode 0 answers 'cup'
    assert bench.within(cost, runs["a"][0][5], 3, 4.0) == 2 and f["budget_4_accuracy"] == 0.5
    assert bench.within(cost, runs["a"][0][5], 3, 1.0) == 1  # the first view always
    # paired against another planner on the same episodes: one that answers 'cup' at once everywhere
    other = [(o, t, 1, "cup", ["cup"] * 3, v, st, g) for o, t, _, _, _, v, st, g in runs["a"]]
    d = bench.paired(cost, runs["a"], {"b": other})["b"]
    assert d["cut_3"] == [0.0, 0.0]  # both right after 3 views
    # after 1 view (4 s fits 2 views for 'a', 'b' stops at 1): a right 1 of 2, b 2 of 2
    assert d["budget_4"][0] == pytest.approx(-0.5)
    assert bench.robot_summary(path, cost) == {"a": f}  # what planners.py reports of its own table


def test_the_robot_seconds_benchmark_stops_budgeted_episodes_at_their_own_entropy(tmp_path):
    from conftest import load_benchmark

    bench = load_benchmark("robot_seconds")
    quarter = "1.5707963;0.0", "1.5707963;1.5707963", "1.5707963;3.1415927"
    header = ["planner", "object", "true", "start", "stopped_at", "early_stop_pred", "pred_1", "pred_2", "pred_3",
              "gain_1", "gain_2", "gain_3", "view_1", "view_2", "view_3"]
    # two classes (log 2 = 0.6931 nats before the first view): entropies 0.4931, 0.2931, 0.0431
    rows = [["a", 0, "cup", 0, 1, "bowl", "bowl", "bowl", "cup", 0.2, 0.2, 0.25, *quarter],
            ["a", 1, "bowl", 0, 1, "bowl", "bowl", "bowl", "bowl", 0.2, 0.2, 0.25, *quarter]]
    path = tmp_path / "per_object.csv"
    path.write_text("\n".join(",".join(map(str, r)) for r in [header, *rows]) + "\n")
    runs = bench.episodes(path)["a"]
    assert [bench.entropy_stop(runs[0], h, 2) for h in (0.5, 0.3, 0.1, 0.01)] == [1, 2, 3, 3]
    cost = RobotTime()
    plain = bench.planner_figures(cost, runs)  # stopped at the first view: 'bowl', right once
    strict = bench.planner_figures(cost, runs, [3, 3])  # on to entropy 0.1: the third view, 'cup' right
    assert plain["budget_24_accuracy"] == 0.5 and strict["budget_24_accuracy"] == 1.0
    assert strict["budget_4_accuracy"] == 0.5  # 4 s hold two views: 'bowl' for both
    assert plain["stop_accuracy"] == strict["stop_accuracy"] == 0.5  # the stop rule's figures stay
    d = bench.paired(cost, runs, {"b": runs}, [3, 3])["b"]
    assert d["budget_12"] == [0.5, 0.5] and d["cut_3"] == [0.0, 0.0]
    with pytest.raises(InputError, match="gain"):
        bench.entropy_stop(runs[0][:7] + (None,), 0.1, 2)
    added = {"a": path}
    assert bench.budget_stops(0.1, {"a": runs}, added) == {"a": [3, 3]}
    with pytest.raises(InputError, match="names 1"):  # one class named: no entropy to rebuild
        bench.budget_stops(0.1, {"a": runs[:1]}, added)
    with pytest.raises(InputError, match=f"--add {path}: .*gain"):  # which CSV lacks its gains
        bench.budget_stops(0.1, {"a": [r[:7] + (None,) for r in runs]}, added)


def test_seconds_validation_stops_budgets_and_its_rule_by_hand():
    from conftest import load_benchmark

    bench = load_benchmark("seconds_validation")
    quarter = np.array([[math.pi / 2, 0.0], [math.pi / 2, math.pi / 2], [math.pi / 2, math.pi]])
    sure, unsure = [0.99, 0.005, 0.005], [0.6, 0.3, 0.1]
    # entropies: sure 0.063 nats (< 0.1), unsure 0.898 (above both); label 0 right, 1 wrong

    class Run:
        def __init__(self, label, probs):
            self.label, self.probs, self.views = label, [np.array(p) for p in probs], quarter[:len(probs)]

    runs = [(0, Run(0, [unsure, sure, sure])),                         # right from the first view, sure at 2
            (1, Run(1, [unsure, [0.3, 0.6, 0.1], [0.02, 0.97, 0.01]]))]  # wrong, then right and sure at 3
    row, eps, rights = bench.setting(runs, [0.1, 0.5])
    assert row["cut_accuracy"] == {"3": 1.0, "6": 1.0, "9": 1.0}
    assert row["travel_deg"]["3"] == pytest.approx(180.0, abs=1e-4)
    f = row["rules"]["0.1"]
    assert f["stop_views"] == 2.5 and f["stop_accuracy"] == 1.0
    move = 0.5 + (math.pi / 2) / 0.5
    assert f["stop_seconds_mean"] == pytest.approx(((0.2 + move) + (0.3 + 2 * move)) / 2)
    # within 4 s two views fit (0.2 + 3.64 s): run 0 right, run 1 answers class 1 at its second view
    assert f["budget_4_accuracy"] == 1.0 and f["budget_4_accuracy_se"] == 0.0
    assert bench.taken_within(eps[1][4], 3, 1.0) == 1 and eps[1][2][0] == 0  # 1 s: the first view, wrong
    _, _, budget = bench.figures(eps[1:], 0.1)
    assert budget[4.0].tolist() == [1.0]  # two views in 4 s: [0.3, 0.6, 0.1] answers class 1
    # threshold 0.5 stops no earlier here: the same figures
    assert row["rules"]["0.5"]["stop_views"] == 2.5
    # the rule: the costs keep their cuts, the better budget accuracy wins; the threshold kept is the
    # highest whose stop accuracy is within a paired standard error of 0.1's
    rows = {"imitation cost 0": row, "imitation cost 1": row}
    chosen, threshold = bench.choose(rows, {n: rights for n in rows}, {n: np.array([0, 1]) for n in rows}, [0.1, 0.5])
    assert chosen == "imitation cost 0" and threshold == 0.5
    # with a budget: the best mean accuracy within 4, 8 and 12 s, a tie going to the strictest
    assert bench.budget_threshold(rows, chosen, [0.5, 0.1]) == 0.1
    looser = {"budget_4_accuracy": 1.0, "budget_8_accuracy": 1.0, "budget_12_accuracy": 1.0}
    strict = {**looser, "budget_12_accuracy": 0.5}
    assert bench.budget_threshold({"c": {"rules": {"0.1": strict, "0.5": looser}}}, "c", [0.1, 0.5]) == 0.5
