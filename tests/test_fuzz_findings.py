"""Hostile inputs found by fuzzing the CLIs, each pinned: one line on stderr, exit 0/1/2, never a traceback."""

import json
import os

import pytest

from wirecheck.oracles import cli

OBJ = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _bytes_path(folder, name: bytes):
    """``folder / name`` for a file name that is not UTF-8; skip where the file system refuses it."""
    path = os.path.join(os.fsencode(folder), name)
    try:
        with open(path, "wb") as fh:
            fh.write(OBJ)
    except OSError as exc:
        pytest.skip(f"this file system refuses non-UTF-8 names ({exc})")
    return path


def test_dataset_with_non_utf8_file_and_folder_names(tmp_path, capsys):
    # A folder holding a mesh named b"bad\xff.obj" and a folder named b"dir\xfd" (os gives their
    # bytes as surrogates, which cannot be written as UTF-8): the run crashed writing report.md
    # (UnicodeEncodeError, exit 3). The reports name them with \x escapes instead.
    data = tmp_path / "data"
    data.mkdir()
    _bytes_path(data, b"bad\xff.obj")
    os.mkdir(os.path.join(os.fsencode(data), b"dir\xfd"))
    _bytes_path(os.path.join(os.fsencode(data), b"dir\xfd"), b"y.obj")
    out = tmp_path / "run"
    code = cli.main(["--report-dir", str(out), "--level", "vertices", "--frames", "1", "--scene", str(data)])
    assert code == 0, capsys.readouterr().err
    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert [m["mesh"] for m in report["meshes"]] == ["bad\\xff.obj", "dir\\xfd/y.obj"]
    assert (report["summary"]["passed"], report["summary"]["cases"]) == (2, 14)      # 7 cameras each, both loaded
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "bad\\xff.obj" in md and "dir\\xfd/y.obj" in md


def test_two_inputs_naming_one_mesh_name_it_printably(tmp_path, capsys):
    # The same folder twice: one error line; its paths escaped too (a surrogate in an error line
    # is not text either).
    data = tmp_path / "data"
    data.mkdir()
    _bytes_path(data, b"bad\xff.obj")
    code = cli.main(["--report-dir", str(tmp_path / "run"), "--level", "vertices", "--frames", "1",
                     "--scene", str(data), "--scene", str(data)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "two meshes named" in err
    assert "bad\\xff.obj" in err and "\udcff" not in err
    assert not (tmp_path / "run").exists()
