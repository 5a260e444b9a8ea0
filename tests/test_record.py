"""The end of every source's case record (oracles.judge.record.finish_record): the faults in the slot the
source left for them, the verdict and reasons, the oracle's precision where its bound was measured, the
per-frame numbers last."""

from __future__ import annotations

from wirecheck.oracles.faults import Fault
from wirecheck.oracles.judge.decide import Verdict
from wirecheck.oracles.judge.evidence import CaseEvidence
from wirecheck.oracles.judge.record import finish_record

COMPARED = {"frames": 2, "vertices": 16, "pixels": 300}
PER_FRAME = [{"frame": 1}, {"frame": 3}]


def test_the_faults_go_in_their_slot_and_the_verdict_and_frames_after_the_measured_fields():
    rec = {"scene": "cube", "faults": [], "lines": {"balance": 0.0}, "compared": COMPARED}
    ev = CaseEvidence(level="frames", compared=COMPARED, frames_checked=2)
    names = (Fault("pixel_offset", {"dx": 0.5, "dy": 0.0}),)
    out = finish_record(rec, ev, Verdict("fail", ("F1@0px 0.40 < 0.98",)), names, PER_FRAME)
    assert out is rec
    assert list(rec) == ["scene", "faults", "lines", "compared", "verdict", "reasons", "per_frame"]
    assert rec["faults"] == [{"name": "pixel_offset", "dx": 0.5, "dy": 0.0}]
    assert rec["verdict"] == "fail" and rec["reasons"] == ["F1@0px 0.40 < 0.98"]
    assert rec["per_frame"] is PER_FRAME


def test_the_oracles_own_bound_is_written_where_it_was_measured_and_the_set_aside_pixels_said():
    ev = CaseEvidence(level="pixels", compared=COMPARED, frames_checked=2, oracle_bound_px=0.0078125)
    rec = finish_record(
        {"faults": []}, ev, Verdict("vacuous", ("oracle_precision: ...",), set_aside=()), (), [], 2.0**-9
    )
    # 2**-9 px: the run's Tolerances.oracle_limit_px as handed in, written out by hand
    assert rec["oracle_bound_px"] == 0.0078125 and rec["oracle_limit_px"] == 0.001953125
    assert rec["oracle_precision"] is True and rec["faults"] == []
    plain = finish_record(
        {"faults": []}, CaseEvidence(level="vertices", compared=COMPARED, frames_checked=2), Verdict("pass", ()), (), []
    )
    assert "oracle_bound_px" not in plain and "oracle_precision" not in plain
