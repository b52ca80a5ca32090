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

"""ROS latency on this machine: the recognizer's step (image received -> next view published),
a full 10-view closed loop over topics with the simulated camera, and a 30 Hz image stream for
60 s (does it keep up, drop nothing it could process, keep its memory flat?). Medians and p99;
last line is JSON."""
import argparse
import resource
import time

import numpy as np
from common import emit
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image

import msg_adapters as ma
from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until
from active_recognition.nodes.recognizer import Recognizer
from active_recognition.nodes.simulated_camera import SimulatedCameraNode


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2 ** 20


def closed_loop(episodes):
    with ros_session() as (ctx, ex):
        cam = SimulatedCameraNode(context=ctx)
        rec = Recognizer(context=ctx, parameter_overrides=[Parameter("entropy_threshold", value=0.0)])
        client = DemoClient(context=ctx)
        for n in (cam, rec, client):
            ex.add_node(n)
        assert spin_until(ex, client.reset.service_is_ready, 10)
        times = []
        for i in range(episodes + 2):
            cam.set_parameters([Parameter("index", value=i * 7 % 500)])
            t = time.perf_counter()
            result = recognize(ex, client)
            assert result is not None and result["views"] == 10, result
            if i >= 2:
                times.append((time.perf_counter() - t) * 1e3)
        return times, np.array(rec.step_ms)


def stream(seconds, hz):
    with ros_session() as (ctx, ex):
        rec = Recognizer(context=ctx)
        client = DemoClient(context=ctx)
        sensor = Node("stream", context=ctx)
        pub = sensor.create_publisher(Image, "depth/image", qos_profile_sensor_data)
        for n in (rec, client, sensor):
            ex.add_node(n)
        assert spin_until(ex, lambda: pub.get_subscription_count() > 0, 10)
        cam = SimulatedCameraNode(context=ctx)  # only to render a realistic image
        depth = cam.sim.capture(*ma.pose_to_camera(ma.view_to_pose(1.0, 0.5)))[0]
        cam.destroy_node()
        published, rss, start = 0, [], time.monotonic()

        def tick():
            nonlocal published
            if rec.core.done and not client.reset_pending:
                client.reset_pending = True
                client.reset.call_async(rec_reset_request()).add_done_callback(
                    lambda f: setattr(client, "reset_pending", False))
            pub.publish(ma.metres_to_image(depth, sensor.get_clock().now().to_msg()))
            published += 1

        client.reset_pending = False
        sensor.create_timer(1.0 / hz, tick)
        while time.monotonic() - start < seconds:
            ex.spin_once(timeout_sec=0.01)
            if len(rss) < int(time.monotonic() - start):
                rss.append(rss_mb())
        spin_until(ex, lambda: False, 0.5)  # let the last images arrive
        lost = published - rec.received
        could_process = rec.received - rec.idle - rec.stale - rec.rejected
        return {"stream_published": published, "stream_received": rec.received,
                "stream_processed": rec.processed, "stream_lost_in_transport": lost,
                "stream_unprocessed": could_process - rec.processed,
                "stream_idle_between_objects": rec.idle, "stream_stale": rec.stale,
                "rss_mb_at_10s": rss[9] if len(rss) > 9 else rss[-1], "rss_mb_at_end": rss[-1],
                "rss_growth_mb": rss[-1] - (rss[9] if len(rss) > 9 else rss[0])}


def rec_reset_request():
    from std_srvs.srv import Trigger
    return Trigger.Request()


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--hz", type=float, default=30.0)
    args = ap.parse_args()
    episodes, steps = closed_loop(args.episodes)
    out = {"step_ms_p50": float(np.percentile(steps, 50)), "step_ms_p99": float(np.percentile(steps, 99)),
           "episode_ms_p50": float(np.median(episodes)), "episode_ms_p99": float(np.percentile(episodes, 99)),
           "episodes": len(episodes)}
    print(f"step {out['step_ms_p50']:.2f} ms p50 / {out['step_ms_p99']:.2f} ms p99; "
          f"10-view episode {out['episode_ms_p50']:.1f} ms p50")
    out.update(stream(args.seconds, args.hz))
    print(f"{args.hz:.0f} Hz for {args.seconds:.0f} s: published {out['stream_published']}, "
          f"processed {out['stream_processed']}, unprocessed {out['stream_unprocessed']}, "
          f"rss growth {out['rss_growth_mb']:.1f} MB")
    emit(out)


if __name__ == "__main__":
    main()
