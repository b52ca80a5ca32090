# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Any depth camera into the model's camera: round trips, analytic geometry, floors, sensors."""
import math

import numpy as np
import pytest
import reference_reprojection as reference  # the whole-frame reprojection, before the crop

from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig, TRUSTED
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera, MISS
from active_recognition.sensing.depth_pixels import fill_holes, spread
from active_recognition.sensing.reach import ViewLimits
from active_recognition.sensing.reprojection import auto_standoff, reproject, seen_centre, support_height
from active_recognition.simulation.depth_sensor import SensorConfig, SimulatedCamera, kinect_sigma, sensor_config

MODEL = CameraConfig()
VIEW = (1.1, 0.7)


def box(lo, hi):
    import trimesh
    return trimesh.creation.box(bounds=[lo, hi])


@pytest.fixture(scope="module")
def chair():
    """A seat on four legs and a back: thin parts, holes between them, flat bottom at z = -0.5."""
    import trimesh
    parts = [box((-0.3, -0.3, -0.05), (0.3, 0.3, 0.02)), box((-0.3, 0.24, 0.02), (0.3, 0.3, 0.5))]
    parts += [box((x, y, -0.5), (x + 0.06, y + 0.06, -0.05)) for x in (-0.3, 0.24) for y in (-0.3, 0.24)]
    mesh = trimesh.util.concatenate(parts)
    return np.asarray(mesh.vertices, np.float32), np.asarray(mesh.faces, np.int32)


def take(sim, view, k, standoff):
    pos = geometry.camera_position(*view, standoff)
    return sim.capture(pos, geometry.optical_rotation(*view))


def simulated(mesh, **sensor):
    sim = SimulatedCamera(SensorConfig(**sensor))
    sim.camera = DepthCamera(mesh[0] * sim.sensor.object_size, mesh[1],
                             CameraConfig(sim.k.height, sim.k.width), intrinsics=sim.k)
    sim.floor_z = float(mesh[0][:, 2].min()) * sim.sensor.object_size
    return sim


def masks_iou(a, b):
    a, b = a < MISS, b < MISS
    return (a & b).sum() / (a | b).sum()


def test_the_model_camera_round_trips_exactly(chair):
    cam = DepthCamera(*chair, MODEL)
    ref = cam.render(VIEW)[0]
    out = reproject(cam.metric(VIEW)[0], MODEL.intrinsics(), geometry.camera_position(*VIEW),
                    geometry.optical_rotation(*VIEW), MODEL)
    assert out.view == pytest.approx(VIEW)
    obj = ref < MISS
    assert np.abs(out.depth[obj] - ref[obj]).max() < 1e-3  # every object pixel, to float error
    assert (out.depth != ref).sum() <= 0.01 * ref.size  # hole filling may close a corner or two
    assert out.object_fraction == pytest.approx(obj.mean(), rel=0.02)


def test_auto_standoff_fills_the_narrower_field_of_view():
    k = geometry.Intrinsics.from_fov(640, 480, math.radians(90))
    half = math.atan(240 / k.fy)  # 480 rows are the narrower side
    assert k.half_fov() == pytest.approx(half)
    assert auto_standoff(k, 2.0) == pytest.approx(1.1 * 2.0 * math.sqrt(3) / 2 / math.sin(half))
    with pytest.raises(ValueError, match="fx"):
        geometry.Intrinsics(64, 64, -1.0, 1.0, 32, 32)


@pytest.mark.parametrize("sensor", [dict(width=640, height=480, fx=385.0, fy=385.0),
                                    dict(fov=60.0), dict(width=200, height=90, fov=87.0,
                                                         object_size=2.5)])
def test_any_lens_size_and_distance_looks_like_the_model_camera(chair, sensor):
    sim = simulated(chair, **sensor)
    size = sim.sensor.object_size
    z, pos, rot = take(sim, VIEW, sim.k, auto_standoff(sim.k, size))
    out = reproject(z, sim.k, pos, rot, MODEL, object_size=size)
    ref = DepthCamera(*chair, MODEL).render(VIEW)[0]
    assert masks_iou(out.depth, ref) > 0.85  # edges quantise differently at another resolution
    both = (out.depth < MISS) & (ref < MISS)
    assert np.median(np.abs(out.depth[both] - ref[both])) < 1.0  # of 255


def test_the_floor_is_found_and_cut_and_a_pose_below_it_gets_no_image(chair):
    plain, floored = simulated(chair, width=320, height=240, fov=87.0), \
        simulated(chair, width=320, height=240, fov=87.0, floor=True)
    k, standoff = plain.k, auto_standoff(plain.k)
    for view in [(0.9, 0.4), (1.3, -2.0), (0.3, 1.0)]:
        a = reproject(*take(plain, view, k, standoff)[:1], k, *take(plain, view, k, standoff)[1:],
                      MODEL)
        b = reproject(take(floored, view, k, standoff)[0], k, *take(floored, view, k, standoff)[1:],
                      MODEL)
        assert b.support[0] == pytest.approx(-0.5, abs=0.02) and a.support is None
        assert masks_iou(a.depth, b.depth) > 0.9  # the legs' feet go with the floor
    below = (2.5, 0.4)  # under the floor plane: the arm cannot get there
    assert take(floored, below, k, standoff) is None
    assert take(plain, below, k, standoff) is not None


def test_support_height_needs_a_layer_beside_the_box():
    rng = np.random.default_rng(0)
    floor = np.c_[rng.uniform(-1.2, 1.2, (4000, 2)), np.full(4000, -0.31)]
    obj = rng.uniform(-0.3, 0.3, (2000, 3))
    height, thickness = support_height(np.r_[floor, obj])
    assert height == pytest.approx(-0.31, abs=1e-6) and 0 < thickness <= 0.05
    assert support_height(obj) is None  # nothing beside the box: nothing to cut


def test_fill_holes_closes_surfaces_but_not_silhouettes():
    rng = np.random.default_rng(1)
    z = np.full((40, 40), np.inf)
    z[10:30, 10:30] = 2.0
    z[35, 2:38] = 3.0  # a thin bar, one pixel high
    holes = z.copy()
    holes[(rng.random(z.shape) < 0.3) & np.isfinite(z)] = np.inf
    filled = fill_holes(holes)
    back = np.isfinite(filled)
    np.testing.assert_array_equal(filled[back], z[back])  # every value filled in is the surface's
    assert not (back & ~np.isfinite(z)).any()  # and nothing outside a surface is filled
    assert back[10:30, 10:30].mean() > 0.95  # from 0.7; missing: a few runs along the square's border
    assert back[35, 2:38].mean() > 0.9  # the bar is whole again, or nearly
    np.testing.assert_array_equal(fill_holes(z), z)  # no holes: nothing grows
    assert not np.isfinite(fill_holes(holes, fillable=np.zeros(z.shape, bool))[holes == np.inf]).any()


def test_fill_holes_does_not_bridge_a_depth_jump():
    # an object (2 m) before a floor (3 m); at each corner of the object the corner pixel and the
    # two beside it across the jump are missing, as a camera's flying-pixel filter leaves them:
    # the corner has two neighbours on each side and no opposite pair on one surface
    z = np.full((30, 30), 3.0)
    holes = np.zeros(z.shape, bool)
    for r, c in ((5, 5), (5, 20), (18, 9)):
        z[r - 4:r + 1, c - 4:c + 1] = 2.0  # the object's bottom-right corner at (r, c)
        holes[r, c] = holes[r - 1, c + 1] = holes[r + 1, c - 1] = True
    filled = fill_holes(np.where(holes, np.inf, z))
    np.testing.assert_array_equal(filled, reference.fill_holes(np.where(holes, np.inf, z)))
    on_a_surface = np.isin(filled, (2.0, 3.0)) | ~np.isfinite(filled)
    assert on_a_surface.all(), filled[~on_a_surface]  # nothing put back mid-air (2.5 before)
    # pixels no ray sampled (a sparse camera's, in the model's image) take the median all the same
    bridged = fill_holes(np.where(holes, np.inf, z), across_jumps=True)
    assert np.isfinite(bridged).all() and (bridged == 2.5).any()
    np.testing.assert_array_equal(bridged, reference.fill_holes(np.where(holes, np.inf, z), across_jumps=True))
    # the same holes where both sides are one surface (depths within agree) are all filled
    near = np.where(z == 3.0, 2.04, 2.0)
    refill = fill_holes(np.where(holes, np.inf, near))
    assert np.isfinite(refill).all() and np.all((refill >= 2.0) & (refill <= 2.04))


def test_kinect_noise_dropout_and_millimetres_match_their_definitions():
    wall = (np.array([[-5, -5, -0.01], [5, -5, -0.01], [5, 5, -0.01], [-5, 5, -0.01]], np.float32),
            np.array([[0, 1, 2], [0, 2, 3]], np.int32))
    view = (0.0, 0.0)  # straight down onto the wall: z-depth = 2.01 everywhere
    clean = take(simulated(wall, width=200, height=200, fov=40.0), view, None, 2.0)[0]
    noisy = take(simulated(wall, width=200, height=200, fov=40.0, noise="kinect"), view, None, 2.0)[0]
    assert np.nanstd(noisy - clean) == pytest.approx(kinect_sigma(2.01), rel=0.05)
    holes = take(simulated(wall, width=200, height=200, fov=40.0, dropout=0.3), view, None, 2.0)[0]
    assert np.isnan(holes).mean() == pytest.approx(0.3, abs=0.01)
    mm = take(simulated(wall, width=50, height=50, fov=40.0, noise="kinect", encoding="16UC1"),
              view, None, 2.0)[0]
    np.testing.assert_allclose(mm * 1000, np.round(mm * 1000), atol=1e-3)
    far = take(simulated(wall, width=50, height=50, fov=40.0, max_range=1.5), view, None, 2.0)[0]
    assert np.isnan(far).all()


def test_edge_dropout_removes_pixels_at_jumps_only(chair):
    plain = take(simulated(chair, width=128, height=128), VIEW, None, 1.0)[0]
    edged = take(simulated(chair, width=128, height=128, edge_dropout=75.0), VIEW, None, 1.0)[0]
    lost = np.isfinite(plain) & np.isnan(edged)
    assert 0 < lost.sum() < 0.3 * np.isfinite(plain).sum()
    pad = np.pad(plain, 1, constant_values=np.nan)
    jump = np.zeros(plain.shape, bool)
    for dr, dc in ((0, 1), (1, 0), (2, 1), (1, 2)):
        with np.errstate(invalid="ignore"):
            jump |= np.abs(pad[dr:dr + 128, dc:dc + 128] - plain) > 0.1 * plain
    assert jump[lost].all()  # every pixel lost sits beside a large jump


def test_edge_dropout_judges_the_real_jumps_not_the_noise(chair):
    """Far away a Kinect's noise between neighbouring pixels exceeds a 75-degree slope; the
    flying-pixel filter still drops only the pixels beside the object's real depth jumps."""
    far = geometry.camera_position(*VIEW, 6.0)
    look = geometry.optical_rotation(*VIEW)
    shots = [simulated(chair, width=128, height=128, fov=20.0, **extra).capture(far, look)[0]
             for extra in ({"edge_dropout": 75.0}, {"edge_dropout": 75.0, "noise": "kinect"})]
    plain, noisy = (np.isfinite(z) for z in shots)
    np.testing.assert_array_equal(plain, noisy)  # the same pixels kept, noise or not
    assert np.nanmax(np.abs(shots[1] - shots[0])) > 0  # and the noise is there


def test_pose_error_is_an_orbit_of_that_angle(chair):
    sim = simulated(chair, pose_error_deg=5.0)
    pos = geometry.camera_position(*VIEW, 1.3)
    rot = geometry.optical_rotation(*VIEW)
    for _ in range(5):
        _, actual, actual_rot = sim.capture(pos, rot)
        cos = actual @ pos / (np.linalg.norm(actual) * np.linalg.norm(pos))
        assert math.degrees(math.acos(min(1.0, cos))) == pytest.approx(5.0, abs=1e-6)
        assert np.linalg.norm(actual) == pytest.approx(1.3)
        assert actual_rot[:, 2] @ (-actual / 1.3) == pytest.approx(1.0)  # still looks at the centre


def test_realsense_preset_is_what_the_demo_promises():
    s = sensor_config("realsense")
    assert (s.width, s.height, s.fx, s.fy, s.noise, s.dropout, s.floor, s.pose_error_deg) == \
        (640, 480, 385.0, 385.0, "kinect", 0.03, True, 2.0) and s.edge_dropout > 0
    with pytest.raises(ValueError, match="camera must be one of"):
        sensor_config("kinect")
    with pytest.raises(ValueError, match="dropout"):
        SensorConfig(dropout=1.5)


def test_an_empty_scene_ends_with_no_object_and_a_far_object_is_still_seen(chair):
    core = ActiveRecognizer(sensing=SensingConfig(max_empty_views=3))
    core.reset(view=VIEW)
    blank = np.full((48, 64), np.nan, np.float32)
    k = geometry.Intrinsics.from_fov(64, 48, math.radians(87))
    statuses = [core.observe(blank, k).status for _ in range(3)]
    assert statuses == ["empty", "empty", "no_object"] and core.done
    assert core.episode.steps == 0 and core.view == pytest.approx(VIEW)  # same view asked again
    core.reset(view=VIEW)
    sim = simulated(chair, width=64, height=48, fov=87.0)
    z, pos, rot = take(sim, VIEW, sim.k, 3 * auto_standoff(sim.k))  # three times too far
    obs = core.observe(z, sim.k, pos, rot)
    assert obs.status in ("classified", "recognized")
    assert obs.object_fraction > core.sensing.min_object_fraction


def test_the_episode_goes_on_from_the_view_actually_taken(chair):
    core = ActiveRecognizer(planner="random")
    core.reset(view=VIEW)
    sim = simulated(chair, width=64, height=64, pose_error_deg=20.0)
    z, pos, rot = sim.capture(*core.requested_pose(sim.k))
    obs = core.observe(z, sim.k, pos, rot)
    actual = geometry.view_from_position(pos - core.centre)[1:]  # around the centre it found
    assert obs.view == pytest.approx(actual) and core.views_taken()[0] == pytest.approx(actual)
    result = obs.result()
    assert set(result) == {"status", "label", "probability", "entropy", "views"}


@pytest.mark.parametrize("view", [(0.9, 0.6), (1.3, 2.2), (2.1, -1.0), (0.02, 0.5), (1.5708, 0.0)])
def test_seen_centre_is_the_box_centre_along_the_axes_a_view_sees_across(view):
    c = np.array([0.08, -0.06, 0.05])
    mesh, config = box((-0.3, -0.2, -0.4), (0.3, 0.2, 0.4)), CameraConfig(128, 128, radius=1.5)
    cam = DepthCamera(mesh.vertices + c, mesh.faces, config)
    pos = geometry.camera_position(*view, 1.5)
    seen = reproject(cam.metric(view)[0], config.intrinsics(), pos, geometry.optical_rotation(*view),
                     CameraConfig(radius=1.5))
    d = np.abs(pos) / 1.5
    told = d < 0.8  # the axes within 37 degrees of the line of sight are not told
    assert told.sum() == (2 if view[0] < 0.1 or view == (1.5708, 0.0) else 3)
    np.testing.assert_allclose(seen_centre(seen.points, pos), np.where(told, c, 0.0), atol=0.01)
    # a few stray points at the box's edge (a noisy floor's, left above the support's cut) do not
    # move it; two hundredths of the points would
    stray = np.tile([[-0.6, -0.6, -0.45]], (len(seen.points) // 400, 1))
    np.testing.assert_allclose(seen_centre(np.r_[seen.points, stray], pos), np.where(told, c, 0.0), atol=0.01)
    many = np.tile(stray[:1], (len(seen.points) // 50, 1))
    assert np.abs(seen_centre(np.r_[seen.points, many], pos) - np.where(told, c, 0.0)).max() > 0.05


def look(core, sim):
    z, pos, rot = sim.capture(*core.requested_pose(sim.k))
    return core.observe(z, sim.k, pos, rot)


def test_the_recognizer_recentres_a_wrong_object_frame_once_at_the_first_view(chair):
    offset = np.array([0.12, -0.1, 0.06])
    assert (np.abs(geometry.camera_position(*VIEW)) < 0.8).all()  # a view that tells every axis
    sim = simulated((chair[0] + np.float32(offset), chair[1]), width=160, height=120, fov=70.0)
    core = ActiveRecognizer(planner="straight")
    core.reset(view=VIEW)
    look(core, sim)
    reach = np.linalg.norm(offset)  # the first TRUSTED of it is left alone
    np.testing.assert_allclose(core.centre, offset * (reach - TRUSTED) / reach, atol=0.02)
    found = core.centre.copy()
    pos, rot = core.requested_pose(sim.k)
    assert np.linalg.norm(pos - found) == pytest.approx(auto_standoff(sim.k))  # around the new centre
    assert rot[:, 2] @ (found - pos) == pytest.approx(auto_standoff(sim.k))    # looking at it
    look(core, sim)
    np.testing.assert_array_equal(core.centre, found)  # once: later views keep the frame
    core.reset(view=VIEW)
    np.testing.assert_array_equal(core.centre, 0.0)  # a new object starts from its given frame
    still = ActiveRecognizer(planner="straight", sensing=SensingConfig(recentre=0.0))
    still.reset(view=VIEW)
    look(still, sim)
    np.testing.assert_array_equal(still.centre, 0.0)
    capped = ActiveRecognizer(planner="straight", sensing=SensingConfig(recentre=0.05))
    capped.reset(view=VIEW)
    look(capped, sim)
    assert np.linalg.norm(capped.centre) == pytest.approx(0.05)
    near = ActiveRecognizer(planner="straight")  # within TRUSTED of the centre: left alone
    near.reset(view=VIEW)
    look(near, simulated((chair[0] + np.float32(offset * 0.5 * TRUSTED / reach), chair[1]), width=160,
                         height=120, fov=70.0))
    np.testing.assert_array_equal(near.centre, 0.0)
    close = ActiveRecognizer(planner="straight", sensing=SensingConfig(standoff=0.8))
    close.reset(view=VIEW)  # so close that the image cuts the object off: its extent is unknown
    z, pos, rot = sim.capture(*close.requested_pose(sim.k))
    assert close.network_input(z, sim.k, pos, rot).cut
    close.observe(z, sim.k, pos, rot)
    np.testing.assert_array_equal(close.centre, 0.0)
    with pytest.raises(ValueError, match="recentre"):
        SensingConfig(recentre=-0.1)


def test_fill_holes_and_spread_match_the_whole_frame_loops():
    """The hole-led fill and the distance-transform spread give what the plain loops over every
    pixel's neighbours give (reference_reprojection), to the bit."""
    rng = np.random.default_rng(3)
    for t in range(150):
        h, w = rng.integers(1, 40, 2)
        z = rng.uniform(1, 1.1, (h, w)) if t % 2 else np.round(rng.uniform(1, 3, (h, w)), 1)
        z[rng.random((h, w)) < rng.uniform(0, 0.8)] = np.inf
        z[rng.random((h, w)) < (0.1 if t % 3 == 0 else 0.0)] = np.nan
        fillable = rng.random((h, w)) < 0.7 if t % 4 == 0 else None
        np.testing.assert_array_equal(fill_holes(z, fillable), reference.fill_holes(z, fillable))
        d = rng.uniform(-3, 3, (h, w)).astype(np.float32).astype(np.float64)  # float32 depths
        d[rng.random((h, w)) < rng.uniform(0.3, 1.0)] = np.nan
        steps = int(rng.integers(0, 40))
        np.testing.assert_array_equal(spread(d, steps), reference.spread(d, steps))


def test_spread_by_rings_equals_the_distance_transform(monkeypatch):
    """Up to RING_STEPS steps spread grows ring by ring; the distance transform it uses beyond
    gives the same bits, on depths that are not float32 numbers too."""
    import active_recognition.sensing.depth_pixels as dp
    rng = np.random.default_rng(5)
    cases = []
    for _ in range(300):
        h, w = rng.integers(1, 50, 2)
        d = rng.uniform(0.3, 4, (h, w))
        d[rng.random((h, w)) < rng.uniform(0, 1)] = np.nan
        cases.append((d, int(rng.integers(1, dp.RING_STEPS + 1))))
    rings = [spread(d, steps) for d, steps in cases]
    monkeypatch.setattr(dp, "RING_STEPS", 0)
    for (d, steps), ring in zip(cases, rings):
        np.testing.assert_array_equal(ring, spread(d, steps))


def frames(sensor, n, seed=0):
    """n frames of procedural test objects from random views, near and farther off."""
    from active_recognition.datasets import default_cache_dir, open_dataset
    rng = np.random.default_rng(seed)
    test = open_dataset("procedural", split="test", cache_dir=default_cache_dir())
    out = []
    for i in rng.choice(len(test), n, replace=False):
        sim = simulated(test.mesh(int(i))[:2], **sensor)
        views = ViewLimits(0.0, 90.0).initial_views(50)  # above the floor (opaque from below)
        view = views[rng.integers(len(views))]
        pos = geometry.camera_position(*view, auto_standoff(sim.k) * rng.uniform(0.9, 1.5))
        out.append((sim.capture(pos, geometry.optical_rotation(*view))[0], sim.k, pos,
                    geometry.optical_rotation(*view)))
    return out


MODEL15 = CameraConfig(radius=1.5)  # the shipped model's
REALSENSE = dict(width=640, height=480, fx=385.0, fy=385.0, noise="kinect", dropout=0.03,
                 edge_dropout=75.0, floor=True)


@pytest.mark.slow
@pytest.mark.parametrize("sensor", [dict(), dict(fov=60.0), REALSENSE])
def test_the_crop_reprojects_as_the_whole_frame_did(sensor):
    """Every pixel read (stride 1), the crop gives the whole-frame reprojection. The one
    difference: floor points outside the crop reach the support's estimate unfilled, which moves
    its thickness by a little (a pixel or two, in a frame or two)."""
    for z, k, pos, rot in frames(sensor, 4):
        old = reference.reproject(z, k, pos, rot, MODEL15)
        new = reproject(z, k, pos, rot, MODEL15, stride=1)
        assert (np.abs(new.depth - old.depth) > 1e-3).sum() <= 8
        assert new.view == pytest.approx(old.view) and new.cut == old.cut
        assert new.object_fraction == pytest.approx(old.object_fraction, abs=0.003)
        assert (new.support is None) == (old.support is None)
        if old.support is not None:
            assert new.support[0] == pytest.approx(old.support[0], abs=1e-3)
        assert len(new.points) == pytest.approx(len(old.points), rel=0.01)
        plain = reproject(z, k, pos, rot, MODEL15, stride=1, fill=False)
        np.testing.assert_array_equal(  # without filling, to float error
            np.round(plain.depth, 3), np.round(reference.reproject(z, k, pos, rot, MODEL15,
                                                                   fill=False).depth, 3))


def test_a_large_image_read_at_a_stride_is_as_near_the_truth():
    """A 640x480 camera gives each of the model's pixels ~7x7 rays; every third row and column
    (2x2 or more rays a model pixel) is as near the ideal camera's image as all of them."""
    clean = {**REALSENSE, "noise": "none", "dropout": 0.0, "edge_dropout": 0.0}
    near_all, near_strided = [], []
    for (z, k, pos, rot), (ideal, *_) in zip(frames(REALSENSE, 4, 5), frames(clean, 4, 5)):
        truth = reproject(ideal, k, pos, rot, MODEL15, stride=1).depth
        full = reproject(z, k, pos, rot, MODEL15, stride=1)
        fast = reproject(z, k, pos, rot, MODEL15)
        assert (fast.support is None) == (full.support is None)
        near_all.append(masks_iou(full.depth, truth))
        near_strided.append(masks_iou(fast.depth, truth))
        assert masks_iou(fast.depth, full.depth) > 0.75
    assert np.mean(near_strided) > np.mean(near_all) - 0.02


def test_the_first_view_is_back_projected_once(chair, monkeypatch):
    """Re-centring reuses the frame's points: one back-projection and one render per image, and
    the centre is the one three whole reprojections found."""
    from active_recognition.runtime import active_recognizer as recognizer
    offset = np.array([0.12, -0.1, 0.06])
    sim = simulated((chair[0] + np.float32(offset), chair[1]), width=160, height=120, fov=70.0)
    core = ActiveRecognizer(planner="straight")
    core.reset(view=VIEW)
    z, pos, rot = sim.capture(*core.requested_pose(sim.k))
    calls = {"frames": 0, "renders": 0}
    frame, render = recognizer.Frame.__init__, recognizer.Frame.render

    def counted(name, f):
        def call(*args, **kwargs):
            calls[name] += 1
            return f(*args, **kwargs)
        return call

    monkeypatch.setattr(recognizer.Frame, "__init__", counted("frames", frame))
    monkeypatch.setattr(recognizer.Frame, "render", counted("renders", render))
    core.observe(z, sim.k, pos, rot)
    assert calls == {"frames": 1, "renders": 1}
    centre = np.zeros(3)  # the old way: reproject, move, reproject, move, reproject
    seen = reference.reproject(z, sim.k, pos, rot, core.camera)
    for _ in range(2):
        found = centre + seen_centre(seen.points, pos - centre)
        reach = np.linalg.norm(found)
        centre = found * min(max(reach - TRUSTED, 0.0), core.sensing.recentre) / reach
        seen = reference.reproject(z, sim.k, pos - centre, rot, core.camera)
    np.testing.assert_allclose(core.centre, centre, atol=1e-9)
