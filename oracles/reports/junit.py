"""JUnit XML for a crosscheck run (``crosscheck --junit-xml FILE``), for CI dashboards.

One ``<testcase classname=SCENE name=CAMERA>`` per case of the report; a case
that did not pass gets a ``<failure>`` whose ``message`` is its faults and
reasons on one line and whose text adds what to check for each fault
(the fault catalogue, oracles.faults). Characters XML cannot hold are written as
escapes (:func:`xml_safe`). A case's ``note`` (what was not compared, and
why) is its testcase's property ``note`` and its ``<system-out>`` (the part
most dashboards show). The ``time`` attributes are the only fields that
change between runs of the same inputs (they come from the report's
``"timing"``). The file is written to a temporary name and renamed into place,
and only a new path or an earlier file of ours is replaced.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

from wirecheck.core.errors import InputError

from wirecheck.core.outputs.output import atomic_write_bytes
from .fault_text import case_cell, hints, notes
from .report import not_passed

#: The root element's name: it marks a file as ours (one we may replace).
SUITES_NAME = "wirecheck crosscheck"


#: Characters XML 1.0 cannot hold, even escaped: C0 controls but tab, newline and carriage return;
#: lone surrogates (a non-UTF-8 file name's bytes, decoded by Python with surrogateescape); U+FFFE, U+FFFF.
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def _escaped(match) -> str:
    code = ord(match.group())
    if 0xDC80 <= code <= 0xDCFF:         # surrogateescape: the file name's original byte
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def xml_safe(text: str) -> str:
    """``text`` with each character XML cannot hold written as a Python escape (``\\x01``, ``\\xff``).

    A scene, camera, candidate or reason may carry any character (a file
    name's control characters or undecodable bytes); ElementTree would write
    them as they are, and the file would not parse.
    """
    return _NOT_XML.sub(_escaped, text)


def _seconds(timing: dict | None) -> float:
    """A case's time from its per-frame stage times (ms) and the frames timed."""
    if not timing:
        return 0.0
    ms = sum(timing.get(k) or 0.0 for k in ("vertex_stage_ms_per_frame", "pixel_stage_ms_per_frame"))
    total = ms * (timing.get("frames_timed") or 0) / 1000.0
    return total if math.isfinite(total) else 0.0


def failure_message(case: dict) -> str:
    """One line: the case's faults, then its reasons."""
    reasons = "; ".join(case.get("reasons") or []) or f"verdict {case['verdict']}"
    return f"faults: {case_cell(case.get('faults') or [], case.get('camera_spec'))}; {reasons}"


def failure_text(case: dict, frames: bool = False) -> str:
    """The failure's body: scene / camera, faults, each reason, and what to check for each fault (``frames``: a
    renderer's own frames, oracles.reports.fault_text.hints; each fault's note)."""
    lines = [f"{case['scene']} / {case['camera']}: verdict {case['verdict']}",
             f"faults: {case_cell(case.get('faults') or [], case.get('camera_spec'))}"]
    lines += [f"reason: {r}" for r in case.get("reasons") or []]
    lines += [f"what to check, {n}: {h}" for n, h in hints(case.get("faults") or [], frames)]
    lines += [f"note, {n}: {t}" for n, t in notes([case])]
    return "\n".join(lines) + "\n"


def junit_xml(report: dict) -> bytes:
    """The report (oracles.runner.run_crosscheck) as JUnit XML bytes (UTF-8)."""
    cases = report["cases"]
    timing = {(t["scene"], t["camera"]): t for t in (report.get("timing") or {}).get("cases", [])}
    failing = {id(c) for c in not_passed(report)}     # a vacuous case allowed by --allow-vacuous is skipped
    skipped = sum(1 for c in cases if c["verdict"] != "pass" and id(c) not in failing)
    wall = (report.get("timing") or {}).get("wall_s") or 0.0
    counts = {"tests": str(len(cases)), "failures": str(len(failing)), "errors": "0", "skipped": str(skipped),
              "time": f"{wall:.3f}"}
    root = ET.Element("testsuites", {"name": SUITES_NAME, **counts})
    suite = ET.SubElement(root, "testsuite", {"name": "crosscheck", **counts})
    props = ET.SubElement(suite, "properties")
    for name in ("candidate", "level", "frames", "every"):
        if report.get(name) is not None:
            ET.SubElement(props, "property", {"name": name, "value": str(report[name])})
    for key, value in (report.get("oracle_gl") or {}).items():     # the GL that drew the oracle's frames
        ET.SubElement(props, "property", {"name": f"oracle_gl_{key}", "value": str(value)})
    for c in cases:
        elem = ET.SubElement(suite, "testcase", {"classname": c["scene"], "name": c["camera"],
                                                 "time": f"{_seconds(timing.get((c['scene'], c['camera']))):.3f}"})
        if c.get("note"):
            ET.SubElement(ET.SubElement(elem, "properties"), "property", {"name": "note", "value": c["note"]})
        if c["verdict"] != "pass" and id(c) not in failing:
            ET.SubElement(elem, "skipped", {"message": "; ".join(c["reasons"]) + " (allowed by --allow-vacuous)"})
        elif c["verdict"] != "pass":
            kind = ",".join(f["name"] for f in c.get("faults") or []) or c["verdict"]
            failure = ET.SubElement(elem, "failure", {"message": failure_message(c), "type": kind})
            failure.text = failure_text(c, report.get("level") == "frames")
        if c.get("note"):
            ET.SubElement(elem, "system-out").text = f"note: {c['note']}\n"
    for elem in root.iter():
        elem.attrib = {k: xml_safe(v) for k, v in elem.attrib.items()}
        if elem.text:
            elem.text = xml_safe(elem.text)
    ET.indent(root)
    return b'<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def check_junit_target(path: Path, option: str = "--junit-xml") -> None:
    """InputError unless ``path`` is new (in an existing folder) or an earlier JUnit file of ours."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{option} {str(path)!r} is a directory: expected a file path")
    if not path.parent.is_dir():
        raise InputError(f"{option} {str(path)!r}: folder {str(path.parent)!r} not found: expected an "
                         "existing folder")
    try:           # a unique temporary name, removed at once: the folder takes files (os.access lies to root)
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise InputError(f"{option} {str(path)!r}: folder {str(path.parent)!r} is not writable ({exc.strerror}): "
                         "expected a writable folder") from None
    if path.exists() or path.is_symlink():
        try:
            ours = path.is_file() and not path.is_symlink() and ET.parse(path).getroot().get("name") == SUITES_NAME
        except (ET.ParseError, OSError):
            ours = False
        if not ours:
            raise InputError(f"{option} {str(path)!r} is a file not written by wirecheck: expected a new path "
                             "or an earlier crosscheck JUnit file (nothing was changed; move it away first)")


def write_junit(path: Path, report: dict) -> Path:
    """Write :func:`junit_xml` to ``path`` atomically (after :func:`check_junit_target`)."""
    path = Path(path)
    check_junit_target(path)
    atomic_write_bytes(path, junit_xml(report))
    return path
