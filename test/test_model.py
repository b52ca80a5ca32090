# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The network: shapes of the encoders, the recurrent cell and the heads, one episode step, the
view increment's bounds and the readouts."""
import math

import numpy as np
import pytest
import torch
import trimesh

from active_recognition.argument_checks import InputError
from active_recognition.model.episode import Episode, EpisodeConfig, entropy, run
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.policies import FixedPlanner
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera, render_views
from active_recognition.training.losses import JointLoss


@pytest.mark.parametrize("encoder,size", [("compact", 64), ("wide", 64), ("alexnet", 227)])
def test_output_shapes_of_every_encoder(encoder, size):
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=7, encoder=encoder, hidden_size=32))
    depth = torch.rand(3, size, size) * 255
    logits, delta, hidden = model(depth, model.init_hidden(3))
    assert logits.shape == (3, 7) and delta.shape == (3, 2) and hidden.shape == (3, 32)
    assert torch.all(delta.abs() <= model.config.max_step)
    assert torch.all(hidden >= 0)  # ReLU cell
    assert model.classify_image(depth).shape == (3, 7)
    with pytest.raises(AssertionError, match=f"{size}x{size}"):
        model(torch.zeros(3, 32, 32), model.init_hidden(3))


def test_the_wide_encoder_reads_one_image_alone_in_eval_mode():
    """Batch-normalised: after training steps (running statistics moved), an image's logits in
    eval mode do not depend on the other images of its batch, as a robot's batch of one needs."""
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=5, encoder="wide", hidden_size=16))
    depth = torch.rand(6, 64, 64) * 255
    opt = torch.optim.SGD(model.parameters(), lr=0.01)
    for _ in range(3):
        opt.zero_grad()
        model.classify_image(depth).sum().backward()
        opt.step()
    bn = model.encoder[1]
    assert not torch.allclose(bn.running_mean, torch.zeros_like(bn.running_mean))
    model.eval()
    with torch.no_grad():
        together = model.classify_image(depth)
        alone = torch.cat([model.classify_image(d[None]) for d in depth])
    torch.testing.assert_close(together, alone, rtol=1e-4, atol=1e-5)


def test_bad_model_configuration_is_refused():
    with pytest.raises(InputError, match="encoder must be one of compact, wide, alexnet, got 'resnet'"):
        ModelConfig(encoder="resnet")
    with pytest.raises(InputError, match=r"max_step must be .* got -1"):
        ModelConfig(max_step=-1)
    with pytest.raises(InputError, match="hidden_size must be an integer from 1 to 8192, got 0"):
        ModelConfig(hidden_size=0)


WIDE = dict(encoder="wide", view_input=True, memory="rnn+max", candidates=5)


@pytest.mark.parametrize("config", [dict(), WIDE])
def test_the_traced_single_step_gives_the_modules_numbers(config):
    """model.single_step (TorchScript, frozen, batch norms folded into the convolutions) against
    the module over a 4-step episode of one object: the same logits, increments and states."""
    from active_recognition.model.network import single_step
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=6, hidden_size=32, feature_size=24, **config))
    with torch.no_grad():  # batch norms that are not the identity
        for m in model.modules():
            if isinstance(m, torch.nn.BatchNorm2d):
                m.running_mean.uniform_(-0.5, 0.5), m.running_var.uniform_(0.5, 2.0)
                m.weight.uniform_(0.5, 1.5), m.bias.uniform_(-0.2, 0.2)
    model.eval()
    fast = single_step(model)
    assert fast is not model
    state = fast_state = model.init_hidden(1)
    with torch.no_grad():
        for t in range(4):
            depth, view = torch.rand(1, 64, 64) * 255, torch.rand(1, 2) * 3
            ours, theirs = fast(depth, fast_state, view), model(depth, state, view)
            for a, b in zip(ours, theirs):
                torch.testing.assert_close(a, b, rtol=1e-4, atol=1e-5)
            fast_state, state = ours[2], theirs[2]


def confident_model(bias):
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=4, hidden_size=16))
    with torch.no_grad():
        model.classify.weight.zero_()
        model.classify.bias.copy_(torch.tensor([bias, 0.0, 0.0, 0.0]))
    return model.eval()


def test_episode_stops_on_the_entropy_threshold():
    ep = Episode(confident_model(12.0), EpisodeConfig(max_views=10, entropy_threshold=0.1))
    ep.reset([1.0, 0.5])
    step = ep.step(torch.full((64, 64), 255.0))
    assert step.entropy.item() < 0.1 and bool(step.done) and ep.stopped_at.item() == 1


def test_a_doubt_holds_a_confident_answer_until_it_clears_or_the_step_limit():
    """Episode.doubt, called after each step's state: where it says True the entropy stop
    waits; the step limit still ends the episode."""
    seen = []

    def doubt(episode, logits):
        assert torch.allclose(logits, torch.tensor([[12.0, 0.0, 0.0, 0.0]]))  # the step's own: the bias alone
        seen.append(episode.steps)
        return torch.tensor([episode.steps < 3])  # in doubt for the first two views
    ep = Episode(confident_model(12.0), EpisodeConfig(max_views=10, entropy_threshold=0.1), doubt=doubt)
    ep.reset([1.0, 0.5])
    dones = [bool(ep.step(torch.full((64, 64), 255.0)).done) for _ in range(3)]
    assert dones == [False, False, True] and ep.stopped_at.item() == 3 and seen == [1, 2, 3]
    ep = Episode(confident_model(12.0), EpisodeConfig(max_views=2, entropy_threshold=0.1),
                 doubt=lambda episode, logits: torch.tensor([True]))
    ep.reset([1.0, 0.5])
    assert [bool(ep.step(torch.full((64, 64), 255.0)).done) for _ in range(2)] == [False, True]


def test_episode_stops_on_the_step_limit_and_records_everything():
    ep = Episode(confident_model(0.5), EpisodeConfig(max_views=4, entropy_threshold=0.1))
    ep.reset([1.0, 0.5])
    dones = [bool(ep.step(torch.full((64, 64), 200.0)).done) for _ in range(4)]
    assert dones == [False, False, False, True] and ep.stopped_at.item() == 4
    assert len(ep.views) == 5 and len(ep.probs) == 4
    # information gain sums to H(p_0) - H(p_T), with p_0 uniform
    total = sum(g.item() for g in ep.info_gain)
    assert math.isclose(total, math.log(4) - entropy(ep.probs[-1]).item(), rel_tol=1e-5)
    for v in ep.views[1:]:  # next views stay valid
        assert 0 <= v[0, 0] <= math.pi and -math.pi <= v[0, 1] < math.pi


def test_an_episodes_state_is_read_through_its_api_and_changed_only_by_its_methods():
    ep = Episode(confident_model(0.5), EpisodeConfig(max_views=4, entropy_threshold=0.1))
    with pytest.raises(RuntimeError, match="reset"):
        ep.step(torch.full((64, 64), 200.0))  # not started
    ep.reset([[1.0, 0.5], [2.0, -1.0]])
    ep.step(torch.full((2, 64, 64), 200.0))
    for name in ("view", "views", "probs", "done", "stopped_at", "size", "hidden"):
        with pytest.raises(AttributeError):
            setattr(ep, name, None)
    ep.done[0] = True  # a copy: the episode goes on
    assert not ep.done.any() and ep.stopped_at.tolist() == [-1, -1]
    twin = ep.fork()
    twin.step(torch.full((2, 64, 64), 200.0))
    twin.stop()
    assert twin.steps == 2 and twin.stopped_at.tolist() == [2, 2] and bool(twin.done.all())
    assert ep.steps == 1 and len(ep.views) == 2 and not ep.done.any()  # left as it was
    with pytest.raises(InputError, match="3 sizes for 2 objects"):
        ep.reset([[1.0, 0.5], [2.0, -1.0]], size=[1.0, 2.0, 3.0])
    with pytest.raises(InputError, match="has no next_view"):
        Episode(ep.model, planner=object())


def test_every_planner_is_a_planner():
    from active_recognition.model.episode import Planner
    from active_recognition.model.policies import make_planner, PLANNERS
    from active_recognition.training.losses import ImitationLoss
    model = RecurrentAttention(ModelConfig(num_classes=3, candidates=8, view_input=True))
    box = trimesh.creation.box(extents=(0.6, 0.4, 0.3))
    cams = [DepthCamera(box.vertices, box.faces)]
    for name in PLANNERS:
        planner = make_planner(name, cams, model=model, fixed_path=[[1.0, 0.0]], labels=[0])
        assert planner is None if name in ("learned", "reinforce") else isinstance(planner, Planner)
    assert isinstance(ImitationLoss(model, 3), Planner)


def test_the_mean_readout_answers_the_mean_of_every_steps_own_probabilities():
    """readout mean: after t views the episode answers, and stops on, the mean of the t steps'
    own softmax; readout last (the paper) answers the last step's. An independent run of the
    model's forward gives each step's own."""
    torch.manual_seed(0)
    images = [torch.rand(2, 64, 64) * 255 for _ in range(4)]
    view = torch.tensor([[1.0, 0.5], [2.0, -1.0]])
    model = RecurrentAttention(ModelConfig(num_classes=5, hidden_size=16, memory="rnn+max")).eval()
    own, state = [], model.init_hidden(2)
    with torch.no_grad():
        for image in images:  # the same views every step: no planner in play
            logits, _, state = model(image, state, view)
            own.append(logits.softmax(-1))
    answers = {}
    for readout in ("last", "mean"):
        model.config.readout = readout
        ep = Episode(model, EpisodeConfig(max_views=4, entropy_threshold=0.0), FixedPlanner(view[:1].numpy()))
        ep.reset(view)
        with torch.no_grad():
            answers[readout] = [ep.step(image) for image in images]
    for t, step in enumerate(answers["last"]):
        torch.testing.assert_close(step.probs, own[t])
    for t, step in enumerate(answers["mean"]):
        torch.testing.assert_close(step.probs, torch.stack(own[:t + 1]).mean(0))
        torch.testing.assert_close(step.entropy, entropy(step.probs))
        torch.testing.assert_close(step.logits.softmax(-1), own[t])  # training reads these
    assert not torch.allclose(answers["mean"][-1].probs, own[-1])
    with pytest.raises(InputError, match="readout must be one of last, mean"):
        ModelConfig(readout="vote")


def an_asymmetric_object():
    """A box with a cylinder off to one side: its mirror image x -> -x is another object."""
    box = trimesh.creation.box(extents=[0.8, 0.5, 0.4])
    post = trimesh.creation.cylinder(radius=0.1, height=0.7)
    post.apply_translation([0.3, 0.15, 0.2])
    return trimesh.util.concatenate([box, post])


def mirror_episode(model, camera, views):
    """Answers of an episode (readout mean+mirror) on `camera` from `views` (T, 2) in turn."""
    ep = Episode(model, EpisodeConfig(max_views=len(views), entropy_threshold=0.0),
                 FixedPlanner(views[1:]))
    with torch.no_grad():
        return [s.probs for s in run(ep, [camera], views[:1])]


def test_the_mirror_readout_averages_each_view_with_the_mirrored_objects_and_is_symmetric():
    """readout mean+mirror: after t views the answer is the mean over the steps of the average of
    two independent runs of the model: one on the object, one on its mirror image (x -> -x,
    a separate mesh, rendered) seen from the mirrored views (theta, pi - phi). Run on the mirror
    image, the same episode answers the same: the two runs swap."""
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=4, hidden_size=16, memory="rnn+max",
                                           view_input=True, readout="mean+mirror")).eval()
    mesh = an_asymmetric_object()
    flipped = mesh.copy()
    flipped.vertices = flipped.vertices * [-1.0, 1.0, 1.0]
    config = CameraConfig(64, 64, radius=1.5)
    camera, mirror_camera = DepthCamera.from_mesh(mesh, config), DepthCamera.from_mesh(flipped, config)
    views = np.array([[1.0, 0.4], [2.0, -1.3], [0.6, 2.8], [1.7, 1.0]])
    mirror_views = np.stack([views[:, 0], np.pi - views[:, 1]], 1)

    def own(cam, vs):
        state, out = model.init_hidden(1), []
        with torch.no_grad():
            for v in vs:
                view = torch.tensor(v[None], dtype=torch.float32)
                logits, _, state = model(torch.from_numpy(cam.render(v[None])).float(), state, view)
                out.append(logits.softmax(-1))
        return out
    both = [(a + b) / 2 for a, b in zip(own(camera, views), own(mirror_camera, mirror_views))]
    answers = mirror_episode(model, camera, views)
    for t, probs in enumerate(answers):
        torch.testing.assert_close(probs, torch.stack(both[:t + 1]).mean(0), atol=1e-5, rtol=1e-4)
    for a, b in zip(answers, mirror_episode(model, mirror_camera, mirror_views)):
        torch.testing.assert_close(a, b, atol=1e-5, rtol=1e-4)
    plain = torch.stack(own(camera, views)).mean(0)
    assert not torch.allclose(answers[-1], plain, atol=1e-4)
    model.train()  # training reads each step's own (compact: no layer acts otherwise in training)
    torch.testing.assert_close(mirror_episode(model, camera, views)[-1], plain, atol=1e-5, rtol=1e-4)


class Scripted(torch.nn.Module):
    """A model that answers a given list of logits, one per step."""

    def __init__(self, logits, readout):
        super().__init__()
        self.config, self.logits = ModelConfig(num_classes=3, readout=readout), list(logits)
        self.anchor = torch.nn.Parameter(torch.zeros(1))

    def init_hidden(self, batch, device=None):
        return torch.zeros(batch, 1)

    def forward(self, depth, hidden, view=None):
        return self.logits.pop(0)[None], torch.zeros(1, 2), hidden


def test_the_mean_readout_stops_on_its_own_entropy():
    """Fairly sure of class 0 (not enough to stop), then sure of class 1: the last step alone
    is sure (it stops, answering 1), the mean of the two is not (it goes on, split between 0
    and 1)."""
    sure = [torch.tensor([4.0, 0.0, 0.0]), torch.tensor([0.0, 20.0, 0.0])]
    stops = {}
    for readout in ("last", "mean"):
        ep = Episode(Scripted(sure, readout), EpisodeConfig(max_views=5, entropy_threshold=0.1),
                     FixedPlanner([[1.0, 1.0]] * 4))
        ep.reset([1.0, 0.5])
        with torch.no_grad():
            ep.step(torch.zeros(64, 64))
            stops[readout] = ep.step(torch.zeros(64, 64))
    assert bool(stops["last"].done) and stops["last"].probs.argmax().item() == 1
    assert not bool(stops["mean"].done)
    mean = (sure[0].softmax(-1) + sure[1].softmax(-1)) / 2
    assert math.isclose(stops["mean"].entropy.item(), entropy(mean).item(), rel_tol=1e-5)
    assert stops["mean"].entropy.item() > 0.6


def tiny_batch():
    rng = np.random.default_rng(0)
    meshes = [trimesh.creation.box(extents=rng.uniform(0.3, 1.0, 3)) for _ in range(3)]
    meshes += [trimesh.creation.cylinder(radius=0.3, height=rng.uniform(0.4, 1.0)) for _ in range(3)]
    for m in meshes:
        m.apply_translation(rng.uniform(-0.1, 0.1, 3))
    cams = [DepthCamera.from_mesh(m, CameraConfig(64, 64)) for m in meshes]
    views = torch.tensor(rng.uniform([0.3, -3], [2.8, 3], (6, 2)))
    return cams, views, torch.tensor([0, 0, 0, 1, 1, 1])


def test_view_head_learns_only_through_the_depth_layer():
    cams, views, labels = tiny_batch()
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=2, hidden_size=32))
    loss, _ = JointLoss(model, steps=4, rule="surface", reduction="sum")(cams, views, labels)
    loss.backward()
    grad = model.locate.weight.grad
    assert grad is not None and grad.abs().sum() > 0
    # cut the depth layer's backward: the view head gets nothing at all
    model.zero_grad()
    ep = Episode(model, EpisodeConfig(max_views=4, entropy_threshold=0.0))
    ep.reset(views)
    loss = 0
    for _ in range(4):
        depth = render_views(ep.view.detach().double(), cams).float()
        loss = loss + torch.nn.functional.cross_entropy(ep.step(depth).logits, labels)
    loss.backward()
    assert model.locate.weight.grad is None or model.locate.weight.grad.abs().sum() == 0


def test_a_few_joint_steps_lower_the_loss():
    cams, views, labels = tiny_batch()
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=2, hidden_size=32))
    net = JointLoss(model, steps=3, rule="paper", reduction="mean")
    opt = torch.optim.Adam(model.parameters(), 1e-3)
    losses = []
    for _ in range(12):
        loss, _ = net(cams, views, labels)
        opt.zero_grad()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert losses[-1] < 0.8 * losses[0], losses


def test_simulated_run_matches_manual_stepping():
    cams, views, _ = tiny_batch()
    model = confident_model(0.3)
    with torch.no_grad():
        out = run(Episode(model, EpisodeConfig(max_views=3)), cams, views)
        ep = Episode(model, EpisodeConfig(max_views=3))
        ep.reset(views)
        for k in range(3):
            depth = np.stack([c.render(v)[0] for c, v in zip(cams, ep.view.numpy())])
            step = ep.step(torch.from_numpy(depth))
            torch.testing.assert_close(step.probs, out[k].probs)


def test_step_weights_uniform_and_early():
    from active_recognition.training.losses import step_weights
    torch.testing.assert_close(step_weights(4), torch.full((4,), 0.25))
    early = step_weights(4, "early")
    h4 = 1 + 1 / 2 + 1 / 3 + 1 / 4
    torch.testing.assert_close(early, torch.tensor([1, 1 / 2, 1 / 3, 1 / 4]) / h4)


def test_joint_loss_is_the_weighted_sum_of_the_per_step_losses():
    from active_recognition.training.losses import step_weights
    cams, views, labels = tiny_batch()
    model = confident_model(0.3)
    with torch.no_grad():
        ce = [torch.nn.functional.cross_entropy(s.logits, labels) for s in
              run(Episode(model, EpisodeConfig(max_views=3, entropy_threshold=0.0)), cams, views, 3)]
        for weighting in ("uniform", "early"):
            loss, _ = JointLoss(model, 3, "surface", "mean", weighting)(cams, views, labels)
            expected = sum(w * c for w, c in zip(step_weights(3, weighting), ce))
            torch.testing.assert_close(loss, expected)


def test_initial_step_sets_the_untrained_increment():
    from active_recognition.model.network import set_initial_step
    model = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=8, max_step=0.8))
    set_initial_step(model, (0.1, -0.7))
    with torch.no_grad():
        delta = model.config.max_step * torch.tanh(model.locate(model.init_hidden(2)))
    torch.testing.assert_close(delta, torch.tensor([[0.1, -0.7]] * 2))
    with pytest.raises(ValueError, match="max_step"):
        set_initial_step(model, (0.0, 0.8))


def test_a_max_memory_keeps_the_running_maximum_of_the_features_beside_the_rnn_state():
    torch.manual_seed(3)
    cfg = ModelConfig(num_classes=4, hidden_size=6, feature_size=5, memory="rnn+max", candidates=7)
    model = RecurrentAttention(cfg).eval()
    plain = RecurrentAttention(ModelConfig(num_classes=4, hidden_size=6, feature_size=5)).eval()
    plain.load_state_dict({k: v for k, v in model.state_dict().items()
                           if not k.startswith(("classify", "locate", "score_views"))}, strict=False)
    depth = torch.rand(5, 2, 64, 64) * 255                        # 5 steps of 2 objects
    state, h = model.init_hidden(2), plain.init_hidden(2)
    assert state.shape == (2, 11)
    with torch.no_grad():
        seen = []
        for t in range(5):
            logits, delta, state = model(depth[t], state)
            _, _, h = plain(depth[t], h)
            seen.append(model.features(depth[t]))
            torch.testing.assert_close(state[:, :6], h)                          # the RNN as before
            torch.testing.assert_close(state[:, 6:], torch.stack(seen).amax(0))  # the running max
            torch.testing.assert_close(logits, model.classify(state))
        assert model.score_views(state).shape == (2, 7) and delta.shape == (2, 2)
        # the privileged look-ahead runs the same step as the episode
        from active_recognition.model.policies import lookahead_logits
        feats = torch.rand(2, 3, 5)
        views = torch.rand(3, 2)
        ahead = lookahead_logits(model, feats, state, views)
        for k in range(3):
            torch.testing.assert_close(ahead[:, k], model.classify(model.advance(feats[:, k], state)))


def test_random_views_in_training_jump_anywhere_at_their_rate_and_keep_the_rest_differentiable():
    from active_recognition.sensing.geometry import wrap_view

    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=8, feature_size=8))
    # the jumps are the episode's, whatever reads the images: a linear encoder in place of the
    # convolutions keeps 4000 episodes (the rates' statistics) a fraction of a second's work
    model.encoder = torch.nn.Sequential(torch.nn.Flatten(), torch.nn.Linear(64 * 64, 8), torch.nn.ReLU())
    depth = torch.rand(4000, 64, 64) * 255
    for rate in (0.0, 0.3, 1.0):
        ep = Episode(model, EpisodeConfig(max_views=3, entropy_threshold=0.0), random_views=rate)
        ep.reset(torch.full((4000, 2), 1.0))
        view = ep.view.clone()
        asked = []  # the increment FC_loc gave within the step, read where the model answers
        hook = model.register_forward_hook(lambda module, args, out: asked.append(out[1]))
        nxt = ep.step(depth).next_view
        hook.remove()
        assert len(asked) == 1
        delta = asked[0]
        own = torch.stack(wrap_view(view[:, 0] + delta[:, 0], view[:, 1] + delta[:, 1]), -1)
        jumped = ~torch.isclose(nxt, own, atol=1e-5).all(-1)
        assert abs(jumped.float().mean().item() - rate) < 0.03
        if rate == 1.0:  # uniform on the sphere: cos(theta) uniform in [-1, 1]
            assert abs(torch.cos(nxt[:, 0]).mean().item()) < 0.05
            assert abs(torch.cos(nxt[:, 0]).var().item() - 1 / 3) < 0.03
        if rate == 0.3:
            nxt[~jumped].sum().backward()
            assert model.locate.weight.grad.abs().sum() > 0


def test_fc_locs_hidden_layer_starts_silent_and_leaves_every_other_layer_as_without_it():
    torch.manual_seed(4)
    plain = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8, candidates=5))
    torch.manual_seed(4)
    grown = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8, candidates=5,
                                           loc_hidden=7))
    theirs = grown.state_dict()
    added = {f"locate_mlp.{i}.{w}" for i in (0, 2) for w in ("weight", "bias")} | {"loc_fitted"}
    assert set(theirs) - set(plain.state_dict()) == added
    for k, v in plain.state_dict().items():  # built last: the same draws for every other layer
        assert torch.equal(v, theirs[k]), k
    hidden = torch.randn(6, 12)
    torch.testing.assert_close(grown.increment(hidden), plain.increment(hidden))
    with torch.no_grad():
        grown.locate_mlp[-1].bias.fill_(100.0)  # then it moves the view, within max_step
    assert torch.allclose(grown.increment(hidden), torch.full((6, 2), grown.config.max_step))
    grown.loc_fitted.fill_(1.0)  # stage loc widens its reach
    bound = grown.config.loc_bound
    assert bound == grown.config.max_step + grown.config.loc_step
    assert torch.allclose(grown.increment(hidden), torch.full((6, 2), bound))


def test_an_episode_told_not_to_mirror_keeps_the_same_states_and_answers_as_mean():
    from active_recognition.model.episode import Episode, EpisodeConfig

    torch.manual_seed(2)
    model = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8, view_input=True,
                                           readout="mean+mirror")).eval()
    depth = torch.rand(3, 2, 64, 64) * 255
    runs = {}
    for mirror in (None, False):
        ep = Episode(model, EpisodeConfig(3, 0.0), planner=None, mirror=mirror)
        ep.reset(torch.tensor([[1.0, 0.3], [0.7, -2.0]]))
        with torch.no_grad():
            runs[mirror] = [(ep.step(d).probs, ep.hidden.clone()) for d in depth]
        assert ep.mirrors == (mirror is None)
    model.config.readout = "mean"
    ep = Episode(model, EpisodeConfig(3, 0.0))
    ep.reset(torch.tensor([[1.0, 0.3], [0.7, -2.0]]))
    with torch.no_grad():
        plain = [ep.step(d).probs for d in depth]
    for (p_m, h_m), (p_n, h_n), p in zip(runs[None], runs[False], plain):
        torch.testing.assert_close(h_m, h_n)  # the mirror pass never touches the state
        torch.testing.assert_close(p_n, p)    # without it, the answer is the plain mean's
        assert not torch.allclose(p_m, p_n)   # with it, the mirror images count


def test_the_wide_encoders_in_place_relus_give_the_numbers_and_gradients_of_plain_ones():
    """Its ReLUs overwrite their batch norm's output: the same outputs and gradients as a copy
    with ReLUs that allocate, in training mode (batch statistics), channels-last as trained."""
    import copy
    from torch import nn
    from active_recognition.training.devices import training_layout
    torch.manual_seed(0)
    model = training_layout(RecurrentAttention(ModelConfig(encoder="wide", num_classes=4)), "cpu")
    plain = copy.deepcopy(model)
    assert any(getattr(m, "inplace", False) for m in model.encoder)
    for m in plain.encoder:
        if isinstance(m, nn.ReLU):
            m.inplace = False
    depth = torch.rand(6, 64, 64) * 255
    for net in (model, plain):
        net.features(depth).square().sum().backward()
    torch.testing.assert_close(model.features(depth), plain.features(depth), rtol=0, atol=0)
    for (name, a), (_, b) in zip(model.named_parameters(), plain.named_parameters()):
        if a.grad is not None:
            torch.testing.assert_close(a.grad, b.grad, rtol=0, atol=0, msg=name)
