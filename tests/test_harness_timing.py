"""What crosscheck's timing counts as harness, candidate and oracle (docs/performance.md#harness-overhead).

Attribution, not speed: a candidate that sleeps in every call must have the
sleep counted as its own time, never as the harness's (speed targets live in
benchmarks/bench_harness.py).
"""

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "data"))
from user_projector import project  # noqa: E402
from wirecheck.oracles.api import check_projector  # noqa: E402

SLEEP_S = 0.15


def slow_project(points, camera):
    time.sleep(SLEEP_S)
    return project(points, camera)


def test_an_external_candidates_calls_are_its_time_and_the_harness_drawing_is_harness():
    report = check_projector(
        slow_project, scenes=["cube"], frames=2, cases=["on_axis"], oracles=("opencv", "pyrender"), isolate=False
    )
    t = report["timing"]
    sleep_ms = 1e3 * SLEEP_S
    # one call for the vertices and one for the clipped segment ends of the drawing, per frame:
    # each at least the sleep, and none of it harness (whose own work is a few ms per frame)
    assert t["candidate_project_ms_per_frame"] >= sleep_ms
    assert t["candidate_draw_ms_per_frame"] >= sleep_ms
    assert t["harness_ms_per_frame"] < sleep_ms
    # the stages add up: harness + candidate + OpenCV + the wait for pyrender = vertex stage + pixel stage + the
    # metrics made beside them (pyrender draws on the GL thread beside the stages: its own time is the oracles',
    # the wait the stage's; the metrics made there after its drawing are the harness's, not the stage's)
    total = (
        t["harness_ms_per_frame"]
        + t["candidate_ms_per_frame"]
        + t["opencv_ms_per_frame"]
        + t["pyrender_wait_ms_per_frame"]
    )
    stages = t["vertex_stage_ms_per_frame"] + t["pixel_stage_ms_per_frame"] + t["pixel_metrics_beside_ms_per_frame"]
    assert abs(total - stages) < 1e-6 * total
    assert t["oracles_ms_per_frame"] == t["opencv_ms_per_frame"] + t["pyrender_ms_per_frame"]
    assert t["harness_overhead_ratio"] == t["harness_ms_per_frame"] / t["oracles_ms_per_frame"]
