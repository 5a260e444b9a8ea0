"""A case's note (what was not compared, and why) is in every report: json, md, html and JUnit XML."""

import copy
import json
import xml.etree.ElementTree as ET
from html.parser import HTMLParser

import pytest
from wirecheck.oracles.judge.case import PIXELS_NOT_COMPARED
from wirecheck.oracles.reports.junit import junit_xml
from wirecheck.oracles.reports.report import _html, markdown


class _Text(HTMLParser):
    """The text of an HTML page (entities decoded) per element, and every tag opened."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.items, self._li = [], [], None

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "li":
            self._li = []

    def handle_endtag(self, tag):
        if tag == "li" and self._li is not None:
            self.items.append("".join(self._li))
            self._li = None

    def handle_data(self, data):
        if self._li is not None:
            self._li.append(data)


def html_items(page: str) -> tuple[list[str], list[str]]:
    p = _Text()
    p.feed(page)
    return p.items, p.tags


def junit_notes(data: bytes) -> dict:
    """``{(scene, camera): (property note, system-out)}`` of the testcases that carry a note."""
    out = {}
    for tc in ET.fromstring(data).iter("testcase"):
        prop = tc.find("properties/property[@name='note']")
        if prop is not None or tc.find("system-out") is not None:
            out[(tc.get("classname"), tc.get("name"))] = (prop.get("value"), tc.find("system-out").text)
    return out


def test_distorted_case_note_in_html_and_junit(tmp_path):
    # The distorted camera at level pixels: its vertices are compared, its pixels are not
    # (oracles/judge/case.py); the note says so in all four outputs, and only for that case.
    from wirecheck.oracles import cli

    out, xml_path = tmp_path / "run", tmp_path / "junit.xml"
    code = cli.main(
        [
            "--report-dir",
            str(out),
            "--junit-xml",
            str(xml_path),
            "--scene",
            "cube",
            "--cases",
            "on_axis,distorted",
            "--frames",
            "2",
        ]
    )
    assert code == 0
    report = json.loads((out / "report.json").read_text())
    assert [c.get("note") for c in report["cases"]] == [None, PIXELS_NOT_COMPARED]
    assert f"- cube / distorted: {PIXELS_NOT_COMPARED}" in (out / "report.md").read_text()
    items, _ = html_items((out / "report.html").read_text())
    assert f"cube / distorted: {PIXELS_NOT_COMPARED}" in items
    assert not [i for i in items if i.startswith("cube / on_axis")]
    assert junit_notes(xml_path.read_bytes()) == {
        ("cube", "distorted"): (PIXELS_NOT_COMPARED, f"note: {PIXELS_NOT_COMPARED}\n")
    }


@pytest.fixture(scope="module")
def one_case_report(tmp_path_factory):
    """The report.json of a one-case run at level vertices (the writers read it like any other)."""
    from wirecheck.oracles import cli

    out = tmp_path_factory.mktemp("notes") / "run"
    assert (
        cli.main(
            ["--report-dir", str(out), "--level", "vertices", "--scene", "cube", "--cases", "on_axis", "--frames", "1"]
        )
        == 0
    )
    return json.loads((out / "report.json").read_text())


def _report(base: dict, note: str) -> dict:
    report = copy.deepcopy(base)
    report["cases"][0]["note"] = note
    return report


def test_note_is_escaped_in_html_and_junit(one_case_report):
    # A note with markup and entities must come back as the same text, not as tags.
    note = 'a <b>bold</b> & "quoted" </li><script>x</script> note'
    report = _report(one_case_report, note)
    items, tags = html_items(_html(report, []))
    assert f"cube / on_axis: {note}" in items
    assert "script" not in tags and tags.count("b") == 1  # the <b> of "cube / on_axis", none from the note
    assert junit_notes(junit_xml(report)) == {("cube", "on_axis"): (note, f"note: {note}\n")}
    assert f"- cube / on_axis: {note}" in markdown(report)


def test_note_of_a_failing_case_sits_beside_its_failure(one_case_report):
    report = _report(one_case_report, "pixels not compared")
    report["cases"][0].update(verdict="fail", reasons=["max vertex error 3 px > 0.5"])
    tc = ET.fromstring(junit_xml(report)).find(".//testcase")
    assert [child.tag for child in tc] == ["properties", "failure", "system-out"]
    assert tc.find("system-out").text == "note: pixels not compared\n"
