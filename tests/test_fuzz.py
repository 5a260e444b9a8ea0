"""Hypothesis over the scene parser, the mesh loader and both CLIs' arguments, in-process (issue 15).

The contract and the input space are in tests/fuzz/contract.py; the long run
(>= 10,000 inputs per CLI) is tests/fuzz/run_fuzz.py, its counts in
docs/reliability.md.
"""

import tempfile
from pathlib import Path

import numpy as np
import pytest
from fuzz.contract import (
    SCENE_TEXTS,
    HypothesisPick,
    Pick,
    crosscheck_argv,
    make_scene_arg,
    mutate_text,
    outside_box,
    renderer_argv,
    run_cli,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from wirecheck.core.errors import InputError
from wirecheck.core.scene.files import load_scene, parse_scene_text
from wirecheck.core.scene.model import Scene

SLOW = settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))


@pytest.fixture(scope="module")
def earlier(tmp_path_factory):
    """An earlier renderer output (with its manifest), copied into some output set-ups."""
    from wirecheck.core.app import cli

    out = tmp_path_factory.mktemp("earlier") / "out"
    assert cli.main(["--frames", "2", "--width", "32", "--height", "24", "--format", "png,gif", "--out", str(out)]) == 0
    return out


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_scene_parser_gives_a_scene_or_one_line(data):
    pick = HypothesisPick(data)
    text = mutate_text(pick, pick.choice(SCENE_TEXTS[:3]))
    try:
        scene = parse_scene_text(text, "f.scene")
    except InputError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("f.scene")
    else:
        assert isinstance(scene, Scene) and scene.vertices.shape[1] == 3


@SLOW
@given(data=st.data())
def test_mesh_loader_gives_a_scene_or_one_line(data):
    pick = HypothesisPick(data)
    with tempfile.TemporaryDirectory() as d:
        (Path(d) / "in").mkdir()
        arg = make_scene_arg(pick, Path(d))
        try:
            scene = load_scene(arg)
        except InputError as exc:
            assert "\n" not in str(exc)
        except OSError:  # names the CLIs turn into one line (too long, not a folder)
            pass
        else:
            assert len(scene.edges) == 0 or scene.edges.max() < len(scene.vertices)


@SLOW
@given(data=st.data())
def test_renderer_contract(data, earlier):
    from wirecheck.core.app import cli

    with tempfile.TemporaryDirectory() as d:
        box = Path(d)
        (box / "in").mkdir()
        argv = renderer_argv(HypothesisPick(data), box, earlier)
        outcome = run_cli(cli.main, argv, box, "renderer")
        assert outcome.problems == [], (argv, outcome)


@pytest.mark.slow
@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_crosscheck_contract(data, earlier):
    from wirecheck.oracles import cli

    with tempfile.TemporaryDirectory() as d:
        box = Path(d)
        (box / "in").mkdir()
        argv = crosscheck_argv(HypothesisPick(data), box, earlier)
        outcome = run_cli(cli.main, argv, box, "crosscheck")
        assert outcome.problems == [], (argv, outcome)


def test_generated_inputs_stay_inside_their_folder(earlier):
    """The generators name no path outside the input's folder: '--scene ..' and '--scene /' made a dataset walk of
    the whole system temporary folder (another program's FIFO there hung the run for 10 minutes)."""
    import random

    for cli, make in (("renderer", renderer_argv), ("crosscheck", crosscheck_argv)):
        values = set()
        for i in range(400):
            with tempfile.TemporaryDirectory() as d:
                box = Path(d)
                (box / "in").mkdir()
                argv = make(Pick(random.Random(f"inside-{cli}-{i}")), box, earlier)
                assert outside_box(argv, box) == [], (cli, i, argv)
                values.update(v for o, v in zip(argv, argv[1:]) if o == "--scene" and not v.startswith(d))
        assert {"in", "nosuch"} <= values, values  # the relative values are still drawn


def test_outside_box_sees_parent_and_root(tmp_path):
    """The check itself: the two values the generator used to draw are outside; the box's own folders are not."""
    assert outside_box(["--scene", "..", "--out", "/", "--report-dir", "in/../..", "--cases", "/x"], tmp_path) == [
        "--scene ..",
        "--out /",
        "--report-dir in/../..",
    ]
    assert outside_box(["--scene", ".", "--scene", str(tmp_path / "in" / ".."), "--out", "out"], tmp_path) == []


#: Complete small meshes of the formats whose readers (trimesh) accept a truncated file (tests/test_hostile.py has one
#: hand-made case each); every shorter prefix must be refused, never read as a smaller mesh.
_TRIANGLE = np.array([[0, 0, 1], [0, 0, 0], [1, 0, 0], [0, 1, 0]], "<f4").tobytes() + b"\0\0"
COMPLETE = {
    "binary.stl": b"\0" * 80 + (2).to_bytes(4, "little") + _TRIANGLE * 2,
    "ascii.stl": (
        "solid s\n" + "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid s\n"
    ).encode(),
    "ascii.ply": (
        b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        b"element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        b"0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n"
    ),
    "mesh.off": b"OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 2 3\n",
}


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(name=st.sampled_from(sorted(COMPLETE)), data=st.data())
def test_a_truncated_mesh_file_is_refused_or_read_whole(name, data):
    full_bytes = COMPLETE[name]
    cut = data.draw(st.integers(0, len(full_bytes) - 1), label="cut")
    with tempfile.TemporaryDirectory() as d:
        whole, part = Path(d) / f"whole_{name}", Path(d) / f"part_{name}"
        whole.write_bytes(full_bytes)
        part.write_bytes(full_bytes[:cut])
        full = load_scene(str(whole))
        try:
            scene = load_scene(str(part))
        except InputError as exc:
            assert "\n" not in str(exc) and str(exc).startswith(str(part))
        else:  # only a cut in the last line's name or newline leaves the mesh whole
            assert (scene.vertices.tolist(), scene.faces) == (full.vertices.tolist(), full.faces), cut


@settings(max_examples=300, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_hostile_png_frames_read_or_one_printable_phrase(data):
    """The image rule on damaged PNGs of every colour type and depth (tests/fuzz/png_inputs.py): a bool image of
    the camera's size or one FrameProblem line without control characters."""
    from fuzz.png_inputs import check_png, hostile_png
    from wirecheck.oracles.candidates.png_frame import FrameProblem, read_png

    pick = HypothesisPick(data)
    width, height = pick.integer(1, 9), pick.integer(1, 5)
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "frame.png"
        path.write_bytes(hostile_png(pick, width, height))
        assert check_png(read_png, FrameProblem, path, width, height) == []
