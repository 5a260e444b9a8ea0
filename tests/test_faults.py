"""The fault catalogue (oracles.faults) and what users read of a fault (oracles.reports.fault_text).

- the catalogue holds every name, in the precedence written out here by hand, with the families and
  sources the judge and the references filter by; docs/diagnosis.md's table is the catalogue's;
- a depth map's and an unprojector's names are the catalogue's too (sources ``depth``, ``points``), a
  reused pixel name with the hint for where it was read; every name oracles/ writes is in it (an AST
  scan of records, ``Fault(...)`` calls and the diagnosis' returned models);
- a cell is the name and its key numbers, at most 60 characters; an ``unexplained`` cell says what
  it is in words, never its matrix; the whole record stays in report.json (rounded in report.md);
- hints and notes are printed once per fault kind under the table: in real runs (a renderer that
  draws nothing, a mirrored one, Pillow's rule; faulty projectors) every cell is <= 60 characters
  and each note is printed once, on screen and in report.html, while report.json keeps one per case.
"""

from __future__ import annotations

import ast
import dataclasses
import json
import re
from pathlib import Path

import numpy as np
import pytest
from wirecheck.oracles import faults
from wirecheck.oracles.diagnosis.depth_faults import DEPTH_FAULTS
from wirecheck.oracles.diagnosis.unproject_faults import UNPROJECT_FAULTS
from wirecheck.oracles.faults import CATALOGUE, NAMES, Fault
from wirecheck.oracles.reports.fault_text import CELL_MAX, below_table, case_cell, cell, full_text, notes

ROOT = Path(__file__).resolve().parent.parent

# ---------------------------------------------------------------- the catalogue

#: The precedence as docs/diagnosis.md states it: a depth flip hides everything, a swap or a mirror
#: changes the picture more than a scale (a rotation used the wrong way round turns it as a whole),
#: an offset is the smallest effect; then a depth map's values (their encoding replaces every value,
#: a float16 step moves them least), the line faults, float32 rounding, and what no simple fault explains.
PRECEDENCE = (
    "depth_flip",
    "clipping_plane",
    "axis_swap",
    "ambiguous",
    "axis_flip",
    "mirror_horizontal",
    "mirror_vertical",
    "rotation_transposed",
    "aspect_mismatch",
    "fov_mismatch",
    "pixel_offset",
    "distortion_mismatch",
    "depth_encoding",
    "depth_reversed",
    "depth_scale",
    "depth_is_range",
    "depth_offset",
    "depth_precision",
    "line_end_bias",
    "line_pixel_bias",
    "raster_rule",
    "precision_limited",
    "unexplained",
)
#: The names a depth map's values and an unprojector's points are given (docs/depth.md's tables).
DEPTH_NAMES = {
    "depth_scale",
    "depth_offset",
    "depth_is_range",
    "depth_reversed",
    "depth_encoding",
    "depth_precision",
    "mirror_vertical",
    "mirror_horizontal",
    "pixel_offset",
    "fov_mismatch",
    "ambiguous",
    "unexplained",
}
POINTS_NAMES = {
    "pixel_offset",
    "mirror_vertical",
    "mirror_horizontal",
    "fov_mismatch",
    "depth_is_range",
    "rotation_transposed",
    "distortion_mismatch",
    "ambiguous",
    "unexplained",
}


def test_the_catalogue_holds_every_name_in_precedence_order():
    assert NAMES == PRECEDENCE
    assert [CATALOGUE[n].precedence for n in NAMES] == list(range(len(PRECEDENCE)))
    for k in CATALOGUE.values():
        assert k.family in faults.FAMILIES and set(k.sources) <= set(faults.SOURCES)
        assert k.source in ("any", "vertices", "pixels", "images", "depth", "points")  # silhouettes: hints only
        for text in [k.hint] + [k.hints[s] for s in k.sources[1:]]:
            assert len(text) > 40, k.name  # a sentence saying what to check


def test_depth_maps_and_unprojectors_are_named_from_the_catalogue():
    assert set(faults.names(source="depth")) == set(DEPTH_FAULTS) == DEPTH_NAMES
    assert set(faults.names(source="points")) == set(UNPROJECT_FAULTS) == POINTS_NAMES
    assert faults.names("depth") == (
        "depth_encoding",
        "depth_reversed",
        "depth_scale",
        "depth_is_range",
        "depth_offset",
        "depth_precision",
    )
    with pytest.raises(KeyError, match="source"):
        faults.names(source="depths")  # a typo is an error, not an empty set


def test_a_reused_name_has_its_sources_hint():
    flip = CATALOGUE["mirror_vertical"]
    assert flip.sources == ("any", "depth", "points", "silhouettes")
    assert flip.hint_for(None) == flip.hint_for("pixels") == flip.hint and "y_px = cy - f y / z" in flip.hint
    assert "glReadPixels returns the bottom row first" in flip.hint_for("depth")
    assert "y_cam = -(v - cy) d / fy" in flip.hint_for("points")
    assert "flip the rows once when reading the frame back" in flip.hint_for("silhouettes")
    # read from depth maps first, from points too: each its own hint
    assert CATALOGUE["depth_is_range"].sources == ("depth", "points")
    assert "depth = range / |(x_n, y_n, 1)|" in Fault("depth_is_range", source="depth").hint
    assert "not along the ray" in Fault("depth_is_range", source="points").hint
    # a name read from one source only keeps its hint; a fault's own hint still comes first
    assert Fault("depth_scale", {"k": 1000.0}, "depth").hint == CATALOGUE["depth_scale"].hint
    assert Fault("pixel_offset", {"hint": "own"}, "points").hint == "own"
    # the source is where it was read, not a field of the record
    assert Fault("mirror_vertical", {}, "points").as_dict() == {"name": "mirror_vertical"}
    with pytest.raises(KeyError, match="source"):
        Fault("mirror_vertical", {}, "unprojector")
    # the selectors of value-selected hints are no source's name (a source key replaces the hint)
    for k in CATALOGUE.values():
        selectors = set(k.hints) - set(k.sources)
        assert not selectors & set(faults.SOURCES), k.name


def test_below_the_table_each_kind_hint_once_for_its_source():
    cases = [{"scene": "cube", "camera": c, "faults": [{"name": "mirror_vertical"}]} for c in ("a", "b")]
    assert below_table(cases, source="depth") == [
        f"  what to check, mirror_vertical: {CATALOGUE['mirror_vertical'].hints['depth']}"
    ]
    assert below_table(cases) == [f"  what to check, mirror_vertical: {CATALOGUE['mirror_vertical'].hint}"]


def test_families_are_the_sets_the_judge_filters_by():
    # each set was a tuple of name strings written in the judge, the diagnosis or the references
    assert faults.names("line_count") == ("line_end_bias", "line_pixel_bias")
    assert faults.names("orientation") == (
        "depth_flip",
        "axis_swap",
        "axis_flip",
        "mirror_horizontal",
        "mirror_vertical",
    )
    assert faults.names("scale", "offset") == ("aspect_mismatch", "fov_mismatch", "pixel_offset")
    assert faults.names(source="pixels") == ("line_end_bias", "line_pixel_bias", "raster_rule")
    assert faults.names(source="vertices") == ("clipping_plane", "distortion_mismatch", "precision_limited")
    # the depth and unprojector names widen none of these sets (rotation_transposed is no orientation of
    # the picture the judge places: its own family)
    assert faults.names("rotation") == ("rotation_transposed",)
    with pytest.raises(KeyError, match="families"):
        faults.names("lines")  # a typo is an error, not an empty set


def test_ordered_sorts_by_precedence_and_keeps_ties_in_place():
    got = faults.ordered(
        [
            {"name": "pixel_offset", "i": 0},
            {"name": "mirror_vertical"},
            {"name": "pixel_offset", "i": 1},
            {"name": "depth_flip"},
        ]
    )
    assert [(f["name"], f.get("i")) for f in got] == [
        ("depth_flip", None),
        ("mirror_vertical", None),
        ("pixel_offset", 0),
        ("pixel_offset", 1),
    ]


def test_a_fault_is_its_record_read_through_the_catalogue():
    record = {
        "name": "fov_mismatch",
        "scale": 0.75,
        "implied_fov_deg": 75.2,
        "implied_ortho_height": None,
        "hint": "the scale is W/H",
    }
    f = Fault.of(record)
    assert f.as_dict() == record and list(f.as_dict()) == list(record)  # report.json's shape and order
    assert f.family == "scale" and f.hint == "the scale is W/H"  # its own hint first
    assert f.shown() == [("implied_fov_deg", "fov", 75.2)]  # None: not implied, not shown
    assert Fault("fov_mismatch").hint == CATALOGUE["fov_mismatch"].hint
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.name = "pixel_offset"
    with pytest.raises(TypeError):
        f.params["scale"] = 1.0  # read-only
    with pytest.raises(KeyError, match="catalogue"):
        Fault("pixel_ofset")


def test_hint_templates_are_filled_from_the_faults_values():
    text = faults.hint_text("unexplained", "dim_lines", level=100, drawn=128)
    assert text.startswith("the frames hold lines, at level 100 of 255") and "under the 128 from which" in text


def _literal(node) -> str | None:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def _produced_names() -> dict:
    """Every fault name oracles/ writes as a literal, with where: the value of a ``"name"`` key (a fault
    record), the first argument of ``Fault(...)`` or ``hint_text(...)``, or, in diagnosis/, the first item
    of a returned or yielded tuple (a name with its params, as the depth and unprojector models give them).

    A regex for ``"name": "..."`` alone missed every name of the depth and unprojector diagnoses: their
    names travel in such tuples and reach the records through a variable. reports/ is left out: it only
    reads faults, and its JUnit XML has ``name`` attributes of its own; the tuple rule is kept to
    diagnosis/, where names are given (elsewhere a returned ``("fail", reasons)`` is no fault).
    """
    found: dict = {}
    for path in sorted((ROOT / "oracles").rglob("*.py")):
        if path.name == "faults.py" or "reports" in path.relative_to(ROOT / "oracles").parts:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = []
            if isinstance(node, ast.Dict):
                names = [_literal(v) for k, v in zip(node.keys, node.values) if k is not None and _literal(k) == "name"]
            elif isinstance(node, ast.Call):
                func = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
                if func in ("Fault", "hint_text") and node.args:
                    names = [_literal(node.args[0])]
            elif (
                isinstance(node, (ast.Return, ast.Yield))
                and isinstance(node.value, ast.Tuple)
                and "diagnosis" in path.parts
            ):
                items = [node.value, *(e for e in node.value.elts if isinstance(e, ast.Tuple))]
                names = [_literal(e.elts[0]) for e in items if len(e.elts) >= 2]
            for name in filter(None, names):
                found.setdefault(name, []).append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def test_every_name_the_code_writes_is_in_the_catalogue():
    produced = _produced_names()
    # the scan reads each way a name is written: a record's "name", a yielded model, a depth map's own
    assert {
        "pixel_offset",
        "raster_rule",
        "depth_flip",
        "unexplained",
        "clipping_plane",
        "depth_scale",
        "depth_encoding",
        "rotation_transposed",
        "mirror_vertical",
    } <= set(produced)
    outside = {name: where for name, where in produced.items() if name not in NAMES}
    assert not outside, f"fault names outside oracles.faults.CATALOGUE: {outside}"


def test_the_docs_table_is_the_catalogue():
    doc = (ROOT / "docs" / "diagnosis.md").read_text(encoding="utf-8")
    generated = re.search(
        r"<!-- catalogue: generated by oracles.faults.markdown_table -->\n(.*?)\n<!-- /catalogue -->", doc, re.S
    )
    assert generated, "docs/diagnosis.md lost its catalogue markers"
    assert generated.group(1) == faults.markdown_table(), (
        "docs/diagnosis.md's catalogue table differs from oracles.faults: paste markdown_table()'s output"
    )
    # and the "Fault names" table above it names the same faults, no more, no fewer
    section = doc.split("## Fault names", 1)[1].split("\n## ", 1)[0]
    documented = set(re.findall(r"^\| `(\w+)` \|", section, re.M))
    assert documented == set(NAMES)


# ---------------------------------------------------------------- cells

CAMERA = {"width": 640, "height": 480, "fov_y_deg": 60.0, "ortho_height": 3.0}


def test_a_cell_is_the_name_and_its_key_numbers():
    frames_offset = {
        "name": "pixel_offset",
        "confidence": 0.97,
        "residual_px": 0.31,
        "dx": 0.5,
        "dy": 0.5,
        "uncertainty_px": 0.21,
        "bias_rule": "gl",
        "rules_read": ["gl", "pillow"],
    }
    assert cell(frames_offset, CAMERA) == "pixel_offset(dx=0.5, dy=0.5)"
    fov = {"name": "fov_mismatch", "scale": 0.6, "implied_fov_deg": 87.48, "implied_ortho_height": None}
    assert cell(fov, CAMERA) == "fov_mismatch(fov=87.48)"
    ortho = {"name": "fov_mismatch", "scale": 0.8, "implied_fov_deg": None, "implied_ortho_height": 3.75}
    assert cell(ortho, CAMERA) == "fov_mismatch(ortho_height=3.75)"
    # 4:3 = 1.3333: four digits would print the nominal, five tell them apart (oracles.reports.fmt)
    assert cell({"name": "aspect_mismatch", "implied_aspect": 1.33264}, CAMERA) == "aspect_mismatch(aspect=1.3326)"
    rule = {"name": "raster_rule", "share_off_by_one_across": 0.1, "offset_px": [0.01, 0.2], "note": "x" * 400}
    assert cell(rule, CAMERA) == "raster_rule"
    assert (
        cell({"name": "clipping_plane", "kind": "z_positive", "near_fit": 1e-9, "hint": "h"})
        == "clipping_plane(z_positive)"
    )
    assert (
        cell({"name": "ambiguous", "alternatives": ["mirror_horizontal", "mirror_vertical"]})
        == "ambiguous(mirror_horizontal or mirror_vertical)"
    )


def test_an_unexplained_cell_says_what_it_is_in_words():
    rotation = {
        "name": "unexplained",
        "residual_px": 4.1234567,
        "residual_rms_px": 2.0,
        "affine": [[0.9781476007338057, -0.20791169081775931], [0.20791169081775931, 0.9781476007338057]],
        "offset": [0.1, 0.2],
        "rotation_deg": 12.000000000000002,
        "candidate_only": 0,
        "oracle_only": 0,
    }
    text = cell(rotation, CAMERA)
    assert text == "unexplained(residual 4.12 px, rotated 12 deg)" and "[" not in text
    # a fit's float noise is no rotation (the lens projector of tests/data/real_world/opencv_k.py on an
    # orthographic camera: rotation_deg -3.2e-15)
    assert cell({**rotation, "rotation_deg": -3.2e-15}) == "unexplained(residual 4.12 px)"
    assert cell({"name": "unexplained", "candidate_pixels": 0, "note": "n"}) == "unexplained(nothing drawn)"
    assert (
        cell({"name": "unexplained", "line_level": 100, "hint": "h"})
        == "unexplained(lines at level 100 of 255, none drawn)"
    )
    # the matrix stays in the full record, rounded to 4 significant digits for report.md
    assert "affine=[[0.9781, -0.2079], [0.2079, 0.9781]]" in full_text([rotation], CAMERA, 4)


def test_a_case_cell_stays_within_its_width():
    many = [
        {"name": "axis_swap"},
        {"name": "mirror_horizontal"},
        {"name": "aspect_mismatch", "implied_aspect": 1.7777777},
        {"name": "fov_mismatch", "implied_fov_deg": 81.23456},
        {"name": "pixel_offset", "dx": 0.5, "dy": 0.25},
    ]
    text = case_cell(many, CAMERA)
    # all five cells joined are 94 characters; names alone 71: the first three names, and a count
    assert text == "axis_swap; mirror_horizontal; aspect_mismatch +2 more" and len(text) <= CELL_MAX
    two = [{"name": "mirror_vertical"}, {"name": "pixel_offset", "dx": 0.5, "dy": 0.5}]
    assert case_cell(two, CAMERA) == "mirror_vertical; pixel_offset(dx=0.5, dy=0.5)"  # 45: as is
    wide = {"name": "line_pixel_bias", "candidate_only": 123456789012, "oracle_only": 987654321098}
    assert cell(wide) == "line_pixel_bias(candidate_only=123456789012)"  # 2 fields: 75 > 60
    assert case_cell([]) == "none"


def test_notes_are_once_per_fault_kind():
    def case(camera, off):
        return {
            "scene": "cube",
            "camera": camera,
            "faults": [
                {"name": "raster_rule", "note": f"the lines are where the oracle's are (centres within {off} px)"}
            ],
        }

    cases = [case("on_axis", "0.10"), case("oblique_roll", "0.20"), case("wide_fov", "0.30")]
    ((name, text),) = notes(cases)
    assert name == "raster_rule" and text.count("centres within") == 1
    assert "(cube / on_axis; 3 cases in all" in text and "0.10" in text
    same = [
        {"scene": s, "camera": "c", "faults": [{"name": "depth_flip", "note": "drew nothing"}]}
        for s in ("cube", "prism")
    ]
    assert notes(same) == [("depth_flip", "drew nothing (2 cases)")]


# ---------------------------------------------------------------- real runs


def _table_cells(stdout: str, cases: int) -> list[str]:
    """The faults column of the console table's ``cases`` rows (the text from the ``faults`` header on)."""
    lines = stdout.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("scene ") and line.rstrip().endswith("faults"))
    start = lines[head].index("faults")
    return [line[start:] for line in lines[head + 1 : head + 1 + cases]]


def _pillow(job: Path) -> None:
    """Draw each frame with Pillow's ImageDraw.line, ends rounded to pixel centres (another aliased rule)."""
    from PIL import Image, ImageDraw
    from wirecheck.core.projector.clipping import clip_to_image
    from wirecheck.oracles.candidates.frames_candidate import frame_inputs, load_job
    from wirecheck.oracles.diagnosis.image_diagnose import oracle_segments

    spec = load_job(job)
    for c in spec["cases"]:
        for rel in c["frames"]:
            k = int(Path(rel).stem.split("_")[-1])
            p, e, cam, m = frame_inputs(job, spec, c["scene"], c["case"], k)
            segs = oracle_segments(p @ m[:3, :3].T + m[:3, 3], e, cam)
            im = Image.new("L", (cam.width, cam.height), 0)
            _, q0, q1 = clip_to_image(segs[:, 0], segs[:, 1], cam.width, cam.height)
            for a, b in zip(q0, q1):
                ImageDraw.Draw(im).line([tuple(np.rint(a)), tuple(np.rint(b))], fill=255)
            (job / rel).parent.mkdir(parents=True, exist_ok=True)
            im.save(job / rel)


@pytest.mark.slow
@pytest.mark.parametrize("drawing", ["nothing", "mirrored", "pillow"])
def test_a_frames_runs_cells_are_short_and_its_notes_printed_once(drawing, tmp_path, capsys):
    from helpers import fill_job
    from wirecheck.oracles.cli import main

    job = tmp_path / "job"
    assert (
        main(["export", str(job), "--scene", "cube", "--cases", "on_axis,oblique_roll,orthographic", "--frames", "2"])
        == 0
    )
    if drawing == "pillow":
        _pillow(job)
    else:
        fill_job(job, (lambda img: np.zeros_like(img)) if drawing == "nothing" else (lambda img: img[:, ::-1].copy()))
    capsys.readouterr()
    main(["--candidate-frames", str(job), "--report-dir", str(tmp_path / "report")])
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "report" / "report.json").read_text())
    cells = _table_cells(out, len(report["cases"]))
    assert len(cells) == 3 and all(len(c) <= CELL_MAX for c in cells), cells
    html = (tmp_path / "report" / "report.html").read_text()
    fault_notes = [f["note"] for c in report["cases"] for f in c["faults"] if f.get("note")]
    if drawing == "nothing":  # every case: nothing drawn, said in a note (one per case in report.json)
        assert len(fault_notes) == 3 and len(set(fault_notes)) == 1
    for note in set(fault_notes):
        # the whole note, or (notes differing by a number) its first case's: once on screen, once in the page
        first = note if len(set(fault_notes)) == 1 else fault_notes[0]
        assert out.count(first) == 1, out
        assert html.count(first.replace("'", "&#x27;")) == 1
    kinds = re.findall(r"^  note, (\w+):", out, re.M)
    assert len(kinds) == len(set(kinds))
    if drawing == "mirrored":
        assert cells[1] == "mirror_horizontal"  # oblique_roll: no symmetry hides it


@pytest.mark.slow
def test_a_projectors_faults_are_short_cells_in_the_assertion():
    import diagnosis_faults as df
    from wirecheck.oracles.api import check_projector, failure_text

    seen = set()
    for name in ("f_transposed", "f_fov", "f_swap_mirror", "f_fov_offset", "f_roll"):
        inject = getattr(df, name)
        report = check_projector(
            lambda p, cam, inject=inject: inject(p, cam),
            scenes=["cube"],
            frames=2,
            cases=["on_axis", "oblique_roll", "orthographic"],
        )
        text = failure_text(report)
        cells = re.findall(r": faults: (.*?); ", text)
        assert cells and all(len(c) <= CELL_MAX for c in cells), cells
        assert not re.search(r"\d{9}", "".join(cells))  # no 16-digit numbers
        for c in report["cases"]:
            seen |= {f["name"] for f in c["faults"]}
            for f in c["faults"]:
                if f["name"] == "unexplained" and "affine" in f:
                    assert len(f["affine"]) == 2  # the full record stays in the report
        hint_kinds = re.findall(r"^  what to check, (\w+):", text, re.M)
        assert len(hint_kinds) == len(set(hint_kinds))  # each kind's hint once
    assert {"unexplained", "fov_mismatch", "axis_swap", "pixel_offset"} <= seen
