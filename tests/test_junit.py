"""crosscheck --junit-xml (oracles/reports/junit.py): one testcase per scene x camera, failures that name the fault."""

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from wirecheck.oracles import cli

DATA = Path(__file__).parent / "data"


@pytest.fixture(autouse=True)
def _data_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(DATA))  # faulty_projectors imports user_projector


def _run(tmp_path, *args, junit="junit.xml"):
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "out"),
            "--junit-xml",
            str(tmp_path / junit),
            "--level",
            "vertices",
            "--frames",
            "2",
            *args,
        ]
    )
    return code, tmp_path / junit


def test_one_testcase_per_scene_and_camera_and_the_faults_as_message(tmp_path):
    code, path = _run(
        tmp_path,
        "--scene",
        "cube",
        "--scene",
        "pyramid",
        "--cases",
        "on_axis,orthographic",
        "--candidate",
        f"{DATA / 'faulty_projectors.py'}:mirrored",
    )
    assert code == 1
    suite = ET.parse(path).getroot().find("testsuite")
    cases = suite.findall("testcase")
    # 2 scenes x 2 cameras, in the report's order; a mirrored projector fails all four
    assert [(c.get("classname"), c.get("name")) for c in cases] == [
        ("cube", "on_axis"),
        ("cube", "orthographic"),
        ("pyramid", "on_axis"),
        ("pyramid", "orthographic"),
    ]
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("4", "4", "0")
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    for case, rec in zip(cases, report["cases"]):
        failure = case.find("failure")
        assert failure.get("type") == "mirror_horizontal"
        assert failure.get("message").startswith("faults: mirror_horizontal; max vertex error")
        assert rec["reasons"][0] in failure.get("message")
        assert "what to check, mirror_horizontal: left and right are exchanged" in failure.text


def test_passing_run_has_no_failures(tmp_path):
    code, path = _run(tmp_path, "--scene", "prism", "--cases", "near_plane,wide_fov,non_square")
    root = ET.parse(path).getroot()
    assert code == 0 and root.get("tests") == "3" and root.get("failures") == "0"
    assert root.find(".//failure") is None and len(root.findall(".//testcase")) == 3


def test_a_crashing_candidate_is_a_failure_not_a_pass(tmp_path):
    code, path = _run(
        tmp_path, "--scene", "cube", "--cases", "on_axis", "--candidate", f"{DATA / 'faulty_projectors.py'}:crashes"
    )
    failure = ET.parse(path).getroot().find(".//testcase/failure")
    assert code == 1 and "ZeroDivisionError: boom" in failure.get("message")


def test_replaces_its_own_file_only(tmp_path, capsys):
    code, path = _run(tmp_path, "--scene", "cube", "--cases", "on_axis")
    assert code == 0
    code, path = _run(tmp_path, "--scene", "cube", "--cases", "on_axis,wide_fov")  # our earlier file: replaced
    assert code == 0 and ET.parse(path).getroot().get("tests") == "2"
    foreign = tmp_path / "results.xml"
    foreign.write_text("<testsuites name='pytest'/>\n")
    code, _ = _run(tmp_path, "--scene", "cube", "--cases", "on_axis", junit="results.xml")
    err = capsys.readouterr().err
    assert code == 2 and "is a file not written by wirecheck" in err and err.count("\n") == 1
    assert foreign.read_text() == "<testsuites name='pytest'/>\n" and not any(
        p.name.startswith(".results.xml") for p in tmp_path.iterdir()
    )


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--suite", "extremes"], "--junit-xml with --suite extremes"),
        (["--sweep"], "--junit-xml with --sweep"),
    ],
)
def test_junit_outside_a_plain_run_is_a_usage_error(tmp_path, capsys, args, needle):
    code = cli.main(["--report-dir", str(tmp_path / "out"), "--junit-xml", str(tmp_path / "j.xml"), *args])
    assert code == 2 and needle in capsys.readouterr().err and not (tmp_path / "j.xml").exists()


def test_missing_folder_is_refused_before_the_run(tmp_path, capsys):
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "out"),
            "--junit-xml",
            str(tmp_path / "no" / "j.xml"),
            "--level",
            "vertices",
            "--scene",
            "cube",
        ]
    )
    assert code == 2 and "folder" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_same_inputs_same_bytes_apart_from_time(tmp_path):
    import re

    runs = []
    for name in ("a.xml", "b.xml"):
        code, path = _run(
            tmp_path,
            "--scene",
            "cube",
            "--cases",
            "on_axis,wide_fov",
            "--candidate",
            f"{DATA / 'faulty_projectors.py'}:mirrored",
            junit=name,
        )
        assert code == 1
        runs.append(re.sub(rb' time="[0-9.]+"', b' time="T"', path.read_bytes()))
    assert runs[0] == runs[1] and runs[0].count(b' time="T"') == 4  # testsuites, testsuite, 2 testcases
