"""oracles.judge.case_loop.measure_frames: one loop feeding each source's frames to the case's measurements.

A stand-in source and stand-in measurements record what the loop hands them, so the loop's
contract is checked alone: each kind of frame given to its measurement in the table's order,
the frame's record shared, the records kept only where the case has per-frame fields, the
surfaces' pixels summed, and a source that stops at a frame ending the case there.
"""

import time

from wirecheck.oracles.judge.case_loop import Measurements, measure_frames


class Frame:
    def __init__(self, k, log):
        self.number, self.log = k, log

    def vertices(self):
        self.log.append(("give vertices", self.number))
        return ("v", self.number)

    def wireframe(self, frame_rec):
        self.log.append(("give wireframe", self.number))
        frame_rec["source's own"] = self.number  # a source's second opinion joins the frame's record
        return ("w", self.number)

    def shaded(self):
        self.log.append(("give shaded", self.number))
        return ("s", self.number)

    def depth_map(self):
        return ("d", self.number)

    def filled(self):
        return {"given": ("f", self.number)}

    def spent(self, kind, seconds):
        self.log.append(("spent", kind, self.number, seconds))


class Measure:
    def __init__(self, name, log, union_px=0, drawn_px=0):
        self.name, self.log, self.union_px, self.drawn_px = name, log, union_px, drawn_px

    def _add(self, k, *args, **kwargs):
        self.log.append((self.name, k, args, kwargs))
        return {"union_px": self.union_px}

    add = add_vertices = _add


def source(numbers, log, stop_at=None):
    for k in numbers:
        if k == stop_at:  # a candidate's error: the source stops giving frames
            return
        yield Frame(k, log)


def test_each_kind_is_given_to_its_measurement_in_order():
    log = []
    m = Measurements(vertices=Measure("vertices", log), wire=Measure("wire", log))
    t0 = time.perf_counter()
    measure_frames(source([1, 3], log), m)
    wall = time.perf_counter() - t0
    # each measurement's own seconds: within the loop's wall time (the stand-ins take microseconds)
    spent = [e[3] for e in log if e[0] == "spent"]
    assert len(spent) == 4 and all(0.0 <= s <= wall for s in spent)
    assert [e[:2] for e in log] == [
        ("give vertices", 1), ("vertices", 1), ("spent", "vertices"),
        ("give wireframe", 1), ("wire", 1), ("spent", "wireframe"),
        ("give vertices", 3), ("vertices", 3), ("spent", "vertices"),
        ("give wireframe", 3), ("wire", 3), ("spent", "wireframe"),
    ]  # fmt: skip
    # the frame's inputs, then its one record (shared by every measurement of the frame)
    wire_calls = [e for e in log if e[0] == "wire"]
    assert wire_calls[0][2][:2] == ("w", 1)
    assert wire_calls[0][2][2] is m.per_frame[0]
    assert m.per_frame == [{"frame": 1, "source's own": 1}, {"frame": 3, "source's own": 3}]


def test_depth_maps_and_filled_frames_keep_their_own_records_and_sum_their_pixels():
    log = []
    m = Measurements(depth=Measure("depth", log, union_px=5), filled=Measure("filled", log, union_px=7))
    measure_frames(source([1, 2, 3], log), m)
    assert m.per_frame == []  # their per-frame numbers live in their own fields
    assert [(e[0], e[1]) for e in log] == [
        ("depth", 1),
        ("filled", 1),
        ("depth", 2),
        ("filled", 2),
        ("depth", 3),
        ("filled", 3),
    ]
    assert log[1][3] == {"given": ("f", 1)}
    assert m.surface_px == 3 * (5 + 7) and m.drawn_px == 36


def test_a_source_that_stops_ends_the_case_there():
    log = []
    m = Measurements(vertices=Measure("vertices", log), shaded=Measure("shaded", log))
    t0 = time.perf_counter()
    measure_frames(source([1, 2, 3, 4], log, stop_at=3), m)
    wall = time.perf_counter() - t0
    assert [r["frame"] for r in m.per_frame] == [1, 2]
    assert (
        all(0.0 <= e[3] <= wall for e in log if e[0] == "spent") and len(log) == 2 * 6
    )  # two frames: each kind given, measured, timed
    assert [e[1] for e in log if e[0] == "shaded"] == [1, 2]


def test_no_frame_no_record():
    m = Measurements(vertices=Measure("vertices", []))
    measure_frames(iter(()), m)
    assert m.per_frame == [] and m.drawn_px == 0


def test_drawn_pixels_are_every_kinds():
    m = Measurements(wire=Measure("wire", [], drawn_px=4), shaded=Measure("shaded", [], drawn_px=6), surface_px=5)
    assert m.drawn_px == 4 + 6 + 5
