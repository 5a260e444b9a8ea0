"""The bounded walk of a job's ``frames/`` names where it was when it stopped.

A link under ``frames/`` to a large folder elsewhere (``/``, a home folder) makes the walk read
MAX_WALK entries and stop; the line said only ``frames: more than N files and folders``, so the
user could not tell which link to remove. Before: no path but ``frames/`` in the line.
"""

from __future__ import annotations

import helpers  # tests/ is on sys.path (rootdir conftest)
import pytest
from wirecheck.oracles.candidates import frames_candidate
from wirecheck.oracles.candidates.frames_candidate import FramesError, load_frames, load_job


def test_the_walk_bound_names_the_folder_it_was_in(tmp_path, monkeypatch):
    job = helpers.blank_job(tmp_path / "job")
    big = tmp_path / "elsewhere"
    (big / "deep").mkdir(parents=True)
    for i in range(8):
        (big / "deep" / f"f{i}").write_bytes(b"")
    (job / "frames/cube/on_axis/out").symlink_to(big)
    monkeypatch.setattr(frames_candidate, "MAX_WALK", 5)  # the job's 4 entries (cube, on_axis, 2 frames) and the link
    # the link's first entry (deep) passes the bound: the line names the folder walked, the link
    with pytest.raises(FramesError) as info:
        load_frames(job, load_job(job))
    line = str(info.value)
    assert line.startswith(f"{job / 'frames'}: more than 5 files and folders: expected the job's frames"), line
    assert f"the walk was in {job / 'frames/cube/on_axis/out'} (a link to a folder elsewhere?)" in line, line
