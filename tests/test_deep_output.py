"""Issue 36, item 6: an output folder nested 1,100 deep (listed in its marker) is walked, not a RecursionError.

Before: the ownership walk (core.outputs.owned) recursed once per level, so a rerun over such a folder
exited 3 with a RecursionError. The walks are iterative now: the rerun replaces the folder, exit 0, and a
user's file at the bottom of a deep folder is still found and refused.
"""

import json
import os

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.outputs.owned import MARKER

OPTIONS = ["--width", "32", "--height", "24", "--frames", "1"]
DEPTH = 1100  # past Python's default recursion limit of 1000


def _nest(frames_dir, depth, last_file=None):
    """``d/d/.../d`` ``depth`` deep under ``frames_dir`` (one level at a time: os.makedirs recurses too);
    the marker rewritten by hand to list them (not by the code under test)."""
    listing = json.loads((frames_dir / MARKER).read_text())
    rel, path = "", frames_dir
    for _ in range(depth):
        rel = f"{rel}d" if not rel else f"{rel}/d"
        path = path / "d"
        os.mkdir(path)
        listing["folders"].append(rel)
    if last_file is not None:
        (path / last_file).write_bytes(b"the user's")
    (frames_dir / MARKER).write_text(json.dumps(listing))
    return path


@pytest.fixture
def deep_cleanup():
    """Folders to remove bottom up after the test: pytest's own clean-up (shutil.rmtree on Python 3.11)
    recurses and would fail on them in a later session."""
    bottoms = []
    yield bottoms
    for bottom in bottoms:
        while bottom.name == "d" and not bottom.is_dir():
            bottom = bottom.parent  # removed by the run, or partly
        for name in os.listdir(bottom):
            if not (bottom / name).is_dir():
                os.unlink(bottom / name)
        while bottom.name == "d":
            os.rmdir(bottom)
            bottom = bottom.parent


def test_rerun_over_a_folder_nested_1100_deep(tmp_path, capsys, deep_cleanup):
    out = tmp_path / "out"
    assert renderer_cli.main([*OPTIONS, "--out", str(out)]) == 0
    deep_cleanup.append(_nest(out / "cube-frames", DEPTH))
    capsys.readouterr()
    rc = renderer_cli.main([*OPTIONS, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert sorted(os.listdir(out / "cube-frames")) == [MARKER, "frame_0001.png"]  # the deep folder was ours


def test_users_file_at_the_bottom_of_a_deep_folder_is_found(tmp_path, capsys, deep_cleanup):
    out = tmp_path / "out"
    assert renderer_cli.main([*OPTIONS, "--out", str(out)]) == 0
    bottom = _nest(out / "cube-frames", DEPTH, last_file="note.txt")
    deep_cleanup.append(bottom)
    capsys.readouterr()
    rc = renderer_cli.main([*OPTIONS, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "note.txt (a file not written by wirecheck)" in err, err
    assert (bottom / "note.txt").read_bytes() == b"the user's"
