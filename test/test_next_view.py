# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The pose the recognizer asks for is upright (image down toward -z, as an arm holds a
camera), and a camera at that roll or at the model's own (optical_rotation, upside down at a
level view) is read the same: the reprojection works from the pose the camera reports."""
import math

import numpy as np
import pytest

from active_recognition.model import checkpoint
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import MISS
from active_recognition.sensing.reprojection import Frame
from active_recognition.simulation.depth_sensor import SensorConfig, SimulatedCamera

GRID = [(t, p) for t in np.linspace(0.15, math.pi - 0.15, 7) for p in np.linspace(-3.0, 3.0, 6)]
POLES = [(0.0, 0.0), (0.0, 1.2), (math.pi, -2.0)]


def look_at(position, centre):
    """An upright optical frame built from scratch: z toward the centre, x level (down x z),
    y = z x x; the columns (x, y, z)."""
    z = np.asarray(centre, np.float64) - position
    z /= np.linalg.norm(z)
    x = np.cross([0.0, 0.0, -1.0], z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], -1)


@pytest.fixture(scope="module")
def core():
    return ActiveRecognizer(checkpoint.shipped("procedural"), seed=0,
                            sensing=SensingConfig(object_size=0.6))


def test_upright_is_the_look_at_frame_and_the_models_turned_half_a_turn():
    for t, p in GRID:
        up = geometry.upright_optical_rotation(t, p)
        np.testing.assert_allclose(up, look_at(geometry.camera_position(t, p, 2.0), np.zeros(3)),
                                   atol=1e-12)
        # the same optical axis, x and y reversed: a roll of 180 degrees about it
        np.testing.assert_allclose(up, geometry.optical_rotation(t, p) @ np.diag([-1.0, -1.0, 1.0]))
        assert up[2, 1] == pytest.approx(-math.sin(t)) and geometry.optical_rotation(t, p)[2, 1] > 0
    batch = np.array(GRID)
    np.testing.assert_allclose(geometry.upright_optical_rotation(batch[:, 0], batch[:, 1]),
                               [geometry.upright_optical_rotation(t, p) for t, p in GRID])


@pytest.mark.parametrize("theta,phi", POLES)
def test_at_the_poles_image_down_points_along_the_meridian_of_phi(theta, phi):
    up = geometry.upright_optical_rotation(theta, phi)
    side = 1.0 if theta == 0 else -1.0  # from above toward azimuth phi, from below away from it
    np.testing.assert_allclose(up[:, 1], side * np.array([math.cos(phi), math.sin(phi), 0.0]),
                               atol=1e-12)
    np.testing.assert_allclose(up[:, 2], [0, 0, -side], atol=1e-12)
    # the limit of the views just off the pole along that meridian
    near = geometry.upright_optical_rotation(abs(theta - 1e-7), phi)
    np.testing.assert_allclose(up, near, atol=1e-6)


def test_the_requested_pose_is_upright_and_looks_at_the_objects_centre(core):
    k = geometry.Intrinsics.from_fov(640, 480, math.radians(87))
    for centre in (np.zeros(3), np.array([0.1, -0.05, 0.08])):
        for view in GRID + POLES:
            core.reset(view=view)
            core.centre = centre
            position, rotation = core.requested_pose(k)
            target = centre * core.sensing.object_size
            forward = (target - position) / np.linalg.norm(target - position)
            np.testing.assert_allclose(rotation[:, 2], forward, atol=1e-9)
            np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)
            assert np.linalg.det(rotation) == pytest.approx(1.0)
            if 0 < view[0] < math.pi:
                assert rotation[2, 1] < 0 and rotation[2, 1] == pytest.approx(-math.sin(view[0]))
                assert rotation[2, 0] == pytest.approx(0.0, abs=1e-12)  # and level: no roll
            else:
                np.testing.assert_allclose(rotation, geometry.upright_optical_rotation(*core.view))


def test_the_simulated_camera_renders_the_roll_it_is_given():
    """A square camera, principal point at the centre: the pose rolled half a turn sees the image
    turned half a turn, a quarter turn a quarter; pixel for pixel, to float32 rounding."""
    sim = SimulatedCamera(SensorConfig(width=48, height=48, fov=70.0))
    sim.load(dataset="procedural", split="test", index=4)
    t, p = 1.2, 0.4
    position = geometry.camera_position(t, p, 1.3)
    model = geometry.optical_rotation(t, p)
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # about optical z
    z = sim.capture(position, model)[0]
    assert np.isfinite(z).mean() > 0.1
    for rotation, turned in ((geometry.upright_optical_rotation(t, p), np.rot90(z, 2)),
                             (model @ quarter, np.rot90(z, 1))):
        seen, _, reported = sim.capture(position, rotation)
        np.testing.assert_array_equal(reported, rotation)
        np.testing.assert_array_equal(np.isnan(seen), np.isnan(turned))
        np.testing.assert_allclose(seen, turned, atol=1e-5)  # metres
    # and not the unturned image: the object is not symmetric under the roll
    assert np.nanmax(np.abs(np.where(np.isnan(z), 0, z) - np.where(np.isnan(np.rot90(z, 2)), 0,
                                                                   np.rot90(z, 2)))) > 0.05


@pytest.mark.parametrize("sensor", [SensorConfig(), SensorConfig(width=96, height=72, fov=60.0)],
                         ids=["virtual", "96x72"])
def test_a_camera_at_either_roll_gives_the_network_the_same_input(core, sensor):
    """The camera that follows the model's own roll (optical_rotation) and the one that follows
    the requested, upright pose see the same points; reprojected from the poses they report, the
    network's input agrees to float32 rounding. Tolerances: the two renders' ray directions are
    float32 products of different matrices, so depths differ by ~1e-6 relative, ~1e-4 on the
    network's 0..255 scale (measured at most 1.2e-4 here); an image read the wrong way round
    moves whole silhouettes, tens to 255 per pixel. The one step's probabilities then agree to
    float32 rounding too. Both cameras read every pixel here (stride 1: a camera much denser
    than the model's is read on every stride-th row and column from pixel (0, 0), a grid that
    the roll moves to other pixels, so it agrees only as closely as two samplings do)."""
    sim = SimulatedCamera(sensor)
    for index, view in ((0, (0.4, 0.3)), (5, (1.2, -2.0)), (9, (1.5708, 1.0)), (2, (2.3, 2.5)),
                        (7, (0.0, 0.7))):
        sim.load(dataset="procedural", split="test", index=index)
        core.reset(view=view)
        core.sensing = SensingConfig(object_size=1.0)
        position, upright = core.requested_pose(sim.k)
        taken = [sim.capture(position, r) for r in (geometry.optical_rotation(*view), upright)]
        for metres, pos, rot in taken:
            assert Frame(metres, sim.k, pos, rot, core.camera).stride == 1
        rolled, level = (core.network_input(m, sim.k, pos, rot) for m, pos, rot in taken)
        assert rolled.object_fraction > 0.02
        np.testing.assert_array_equal(rolled.depth < MISS, level.depth < MISS)
        np.testing.assert_allclose(rolled.depth, level.depth, atol=1e-3)
        assert rolled.view == pytest.approx(level.view, abs=1e-12)
        probs = []
        for metres, pos, rot in taken:
            core.reset(view=view)
            probs.append(core.observe(metres, sim.k, pos, rot).probs)
        np.testing.assert_allclose(probs[0], probs[1], atol=1e-5)
