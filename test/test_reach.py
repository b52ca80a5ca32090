# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0


"""The views a robot can take: elevation limits kept by every planner and the initial view,
views found unreachable never asked for again, the simulated floor, and the physical bounds
every input of the recognizer is checked against."""
import math

import numpy as np
import pytest
import torch
from conftest import sure_or_not

from active_recognition.argument_checks import InputError
from active_recognition.datasets.twins import make_shape
from active_recognition.model.episode import Episode, EpisodeConfig
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.policies import make_planner
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.sensing import camera_input_bounds, geometry
from active_recognition.sensing.depth_layer import DepthCamera
from active_recognition.sensing.reach import BLOCK_RADIUS, Reach, ViewLimits, angles_between
from active_recognition.simulation.depth_sensor import SensorConfig, SimulatedCamera


def elevations(views):
    return 90 - np.degrees(np.asarray(views, dtype=np.float64).reshape(-1, 2)[:, 0])


def test_limits_are_checked_and_name_the_field():
    with pytest.raises(InputError, match=r"min_elevation \(10\) must not exceed max_elevation"):
        ViewLimits(10.0, -10.0)
    with pytest.raises(InputError, match=r"min_elevation must be a finite number in \[-90, 90\]"):
        ViewLimits(-100.0)


def test_initial_views_are_the_papers_50_within_the_limits():
    np.testing.assert_array_equal(ViewLimits().initial_views(), geometry.fibonacci_views(50))
    floor = ViewLimits(0.0, 90.0).initial_views()
    assert len(floor) == 25 and elevations(floor).min() >= 0
    band = ViewLimits(31.0, 31.0).initial_views()  # none of the 50 lies on it: clamped onto it
    assert len(band) == 50 and np.allclose(elevations(band), 31.0)


def small_model(candidates=10):
    torch.manual_seed(1)
    return RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8,
                                          candidates=candidates)).eval()


PLANNERS = ["learned", "reinforce", "random", "straight", "fixed", "imitation", "fixed+imitation",
            "oracle", "greedy"]


def views_of(name, reach, steps=12):
    """Every view an episode of `steps` random images asks for, from a start below the floor."""
    model = small_model()
    cams = [DepthCamera(*make_shape(0, 3, False))]
    planner = make_planner(name, cams, seed=2, candidates=20, model=model,
                           fixed_path=[(2.8, 0.3), (0.2, 1.0)], labels=[1])  # one from below
    episode = Episode(model, EpisodeConfig(steps, 0.0), planner, reach=reach)
    episode.reset(torch.tensor([2.6, 0.4]))
    gen = torch.Generator().manual_seed(0)
    with torch.no_grad():
        for _ in range(steps):
            episode.step(torch.rand(1, 64, 64, generator=gen) * 255)
    return torch.cat(episode.views).numpy()


@pytest.mark.parametrize("name", PLANNERS)
def test_every_planner_and_the_initial_view_keep_to_the_limits(name):
    views = views_of(name, Reach(ViewLimits(10.0, 60.0)))
    assert elevations(views).min() >= 10 - 1e-4 and elevations(views).max() <= 60 + 1e-4, name
    if name in ("random", "straight", "fixed"):  # without limits these do leave the band
        free = elevations(views_of(name, None))
        assert free.min() < 10 or free.max() > 60


def test_candidate_planners_mask_rather_than_clamp():
    reach = Reach(ViewLimits(0.0, 90.0))
    views = views_of("imitation", reach)[1:]
    candidates = geometry.fibonacci_views(10)
    assert angles_between(views, candidates).min(1).max() < 1e-6  # each view is a candidate


def floor_camera(**sensor):
    sim = SimulatedCamera(SensorConfig(width=64, height=64, **sensor), seed=3)
    sim.load(dataset="procedural", split="test", index=4)
    return sim


def test_a_view_found_unreachable_is_never_asked_for_again():
    core = ActiveRecognizer(planner="straight", seed=1, limits=ViewLimits(0.0, 90.0),
                            sensing=SensingConfig(max_unreachable_views=2))
    sim = floor_camera()
    core.reset()
    blocked = core.view
    moved = core.view_unreachable()
    assert moved.status == "moved" and not moved.done
    asked = [core.view]
    while not core.done:
        obs = core.observe(*sim.capture(*core.requested_pose(sim.k))[:1], sim.k)
        asked.append(core.view)
    assert obs.status == sure_or_not(obs.result(), core.confidence)
    assert angles_between(asked, [blocked]).min() > BLOCK_RADIUS
    assert elevations(asked).min() >= -1e-4


def test_unreachable_views_in_a_row_end_the_episode_with_no_image_and_the_label_so_far():
    core = ActiveRecognizer(planner="straight", seed=1, limits=ViewLimits(0.0, 90.0),
                            sensing=SensingConfig(max_unreachable_views=2))
    sim = floor_camera()
    core.reset()
    assert core.view_unreachable().status == "moved"
    obs = core.observe(sim.capture(*core.requested_pose(sim.k))[0], sim.k)
    assert obs.status == "classified"
    assert core.view_unreachable().status == "moved"  # an image came between: a new run
    end = core.view_unreachable()
    assert end.status == "no_image" and end.done and core.done
    result = end.result()
    assert result["status"] == "no_image" and result["views"] == 1
    assert result["label"] == obs.label and result["probability"] == pytest.approx(obs.probs.max())
    with pytest.raises(RuntimeError, match="reset"):
        core.view_unreachable()
    core.reset()
    assert not core.done and core.view_unreachable().status == "moved"  # blocks start afresh
    silent = ActiveRecognizer(seed=1, limits=ViewLimits(0.0, 90.0))
    silent.reset()
    silent.view_unreachable()
    assert silent.view_unreachable().result() == {"status": "no_image", "label": "",
                                                  "probability": 0.0, "entropy": None, "views": 0}


def test_no_free_view_left_ends_the_episode():
    core = ActiveRecognizer(seed=1, limits=ViewLimits(89.0, 90.0),
                            sensing=SensingConfig(max_unreachable_views=1000))
    core.reset()
    statuses = [core.view_unreachable().status for _ in range(60) if not core.done]
    assert statuses[-1] == "no_image" and statuses[:-1] == ["moved"] * (len(statuses) - 1)
    assert len(statuses) < 60


def test_the_floor_is_opaque_from_below_and_a_pose_below_it_gets_no_image():
    sim = floor_camera(floor=True)
    view = (2.4, 0.5)  # from below
    position = geometry.camera_position(*view, 1.5)
    assert not sim.reachable(position) and sim.capture(position, geometry.optical_rotation(*view)) is None
    sim.reachable = lambda p: True  # as if an arm's error had taken it there
    z, pos, rot = sim.capture(position, geometry.optical_rotation(*view))
    points = pos + (sim.k.rays() * z[..., None]) @ rot.T
    seen = np.isfinite(z)
    assert seen.any() and np.allclose(points[seen][:, 2], sim.floor_z, atol=1e-3)  # floor only


def test_a_share_of_requests_goes_unanswered():
    sim = floor_camera(unanswered=0.2)
    view = (1.0, 0.5)
    pose = geometry.camera_position(*view, 1.5), geometry.optical_rotation(*view)
    lost = sum(sim.capture(*pose) is None for _ in range(200))
    assert 25 <= lost <= 55
    assert all(floor_camera().capture(*pose) is not None for _ in range(5))


def realsense():
    return geometry.Intrinsics(640, 480, 385.0, 385.0, 319.5, 239.5)


@pytest.mark.parametrize("k,field", [
    (geometry.Intrinsics(64, 64, 60.0, 60.0, 320.0, 240.0), "k[2] (cx)"),  # another size's K
    (geometry.Intrinsics(640, 480, 1e-3, 1e-3, 319.5, 239.5), "k[0] (fx)"),
    (geometry.Intrinsics(640, 480, 1e7, 1e7, 319.5, 239.5), "k[0] (fx)"),
    (geometry.Intrinsics(640, 480, 385.0, 1500.0, 319.5, 239.5), "k[4] (fy)"),
    (geometry.Intrinsics(640, 480, 385.0, 385.0, 319.5, 479.0), "k[5] (cy)"),
])
def test_implausible_intrinsics_are_refused_by_field(k, field):
    with pytest.raises(InputError, match=re_escape(field)):
        camera_input_bounds.check_intrinsics(k)


def re_escape(text):
    import re
    return re.escape(text)


def test_real_cameras_pass_and_poses_and_stamps_are_bounded():
    assert camera_input_bounds.check_intrinsics(realsense()) == realsense()
    own = geometry.Intrinsics.from_fov(64, 64, math.radians(120))  # the model's own camera
    assert camera_input_bounds.check_intrinsics(own) == own
    camera_input_bounds.check_camera_position([0.0, -1.2, 0.4])
    for far in ([1e6, 0, 0], [0, 0, 0]):
        with pytest.raises(InputError, match="pose.position is"):
            camera_input_bounds.check_camera_position(far)
    assert camera_input_bounds.check_clock(100.5, 100.0, 5.0) == 100.5
    with pytest.raises(InputError, match=r"header.stamp is -3.6e\+03 s from this node's clock"):
        camera_input_bounds.check_clock(100.0, 3700.0, 5.0)


def test_object_size_and_standoff_have_physical_bounds():
    with pytest.raises(InputError, match="object_size must be a finite number in"):
        SensingConfig(object_size=1e300)
    with pytest.raises(InputError, match="standoff must be"):
        SensingConfig(standoff=1e6)


def test_evaluate_keeps_every_planner_and_start_inside_the_limits(tmp_path, monkeypatch, dataset_cache):
    from active_recognition.evaluation.evaluate import EvalConfig, evaluate

    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    cfg = EvalConfig(planners=("learned", "random", "straight", "oracle"), objects=6, steps=4,
                     shared=False, limits={"min_elevation": 0.0}, out=str(tmp_path / "out"), oracle_candidates=20,
                     trajectory_figures=0, starts=2)
    results = evaluate(cfg, progress=False)
    top = ViewLimits(0.0, 90.0)
    for name, ro in results.items():
        assert top.allows(ro.views.reshape(-1, 2)).all(), name
        assert set(ro.starts) <= set(range(len(top.initial_views(50))))
        np.testing.assert_allclose(ro.views[:, 0], top.initial_views(50)[ro.starts])
    with pytest.raises(InputError, match=r"min_elevation \(10\) must not exceed max_elevation \(5\)"):
        EvalConfig(limits={"min_elevation": 10, "max_elevation": 5})


def test_training_keeps_to_the_limits_and_imitation_never_targets_a_view_outside():
    from active_recognition.training.losses import ImitationLoss, JointLoss
    from active_recognition.training.train import TrainConfig

    with pytest.raises(InputError, match="must not exceed"):
        TrainConfig(limits={"min_elevation": 30, "max_elevation": 0})
    top = ViewLimits(0.0, 90.0)
    torch.manual_seed(0)
    model = small_model(candidates=20)
    cams = [DepthCamera(*make_shape(k, 3, False)) for k in range(2)]
    starts = top.initial_views(50)[:2]
    seen = []
    loss = ImitationLoss(model, steps=4, mix=1.0, limits=top)  # always the teacher's target
    original = loss.next_view
    loss.next_view = lambda ep, step: seen.append(original(ep, step)) or seen[-1]
    loss(cams, starts, torch.tensor([0, 1]))
    assert len(seen) == 4 and all(top.allows(v).all() for v in seen)
    joint = JointLoss(model, 4, "surface", "mean", random_views=0.5, limits=top)
    value, _ = joint(cams, starts, torch.tensor([0, 1]))
    value.backward()  # differentiable through the clamped views
    assert model.locate.weight.grad is not None
