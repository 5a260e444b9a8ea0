"""Issue 36, item 3: the rename journal is checked before it is finished, never trusted.

Before: a ``.wirecheck-journal.json`` planted in ``--out`` made the renderer replace any file it named (a
user's thesis.tex, given its true hash, exit 0), delete a user's folder named like a temporary folder that
had no staging tag, and ``"folders": 5`` gave exit 3 with the journal kept, so every later run exited 3.
Now (core.outputs.staging, rule 3) a journal may name only the run's own output names and a tagged
temporary folder of its own; anything else is one line, exit 2, the journal left in place and the message
saying how to clear it; once cleared, the next run works.
"""

import hashlib
import json
import os

import pytest
from wirecheck.core.app import cli as renderer_cli
from wirecheck.core.outputs.owned import TAG
from wirecheck.core.outputs.staging import JOURNAL

OPTIONS = ["--width", "32", "--height", "24", "--frames", "1"]
THESIS = b"\\documentclass{article} the user's thesis\n"


def _render(out, capsys):
    capsys.readouterr()
    rc = renderer_cli.main([*OPTIONS, "--out", str(out)])
    return rc, capsys.readouterr().err


def _journal(out, **fields):
    data = {
        "wirecheck_journal": 1,
        "tmp": ".wirecheck-abc123.tmp",
        "names": ["cube-report.txt"],
        "folders": [],
        "manifest": {},
    }
    data.update(fields)
    (out / JOURNAL).write_text(json.dumps(data))
    return (out / JOURNAL).read_bytes()


def _assert_refused(out, capsys, journal_bytes):
    rc, err = _render(out, capsys)
    assert rc == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert JOURNAL in err and "delete" in err and str(out / JOURNAL) in err, err
    assert (out / JOURNAL).read_bytes() == journal_bytes  # left in place
    assert not (out / "cube-report.json").exists()
    os.unlink(out / JOURNAL)  # what the message says to do
    assert _render(out, capsys)[0] == 0  # then the next run works


def test_journal_naming_a_users_file_never_replaces_it(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_bytes(THESIS)
    tmp = out / ".wirecheck-abc123.tmp"
    tmp.mkdir()
    (tmp / TAG).write_bytes(b"")
    (tmp / "thesis.tex").write_bytes(b"replaced!\n")
    digest = hashlib.sha256(THESIS).hexdigest()  # its true hash: a manifest would trust it
    journal = _journal(out, names=["thesis.tex"], manifest={"thesis.tex": digest})
    _assert_refused(out, capsys, journal)
    assert (out / "thesis.tex").read_bytes() == THESIS


def test_journal_naming_an_untagged_folder_never_deletes_it(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    users = out / ".wirecheck-mydata.tmp"  # named like a temporary, no staging tag
    users.mkdir()
    (users / "data.csv").write_bytes(b"1,2,3\n")
    journal = _journal(out, tmp=users.name, names=["cube-report.txt"])
    _assert_refused(out, capsys, journal)
    assert (users / "data.csv").read_bytes() == b"1,2,3\n"


@pytest.mark.parametrize(
    "fields",
    [
        {"folders": 5},
        {"names": "cube-report.txt"},
        {"manifest": {"a": "x"}},
        {"tmp": "../elsewhere"},
        {"names": ["../../etc"]},
        {"manifest": []},
    ],
    ids=["folders_int", "names_str", "hash_bad", "tmp_outside", "name_outside", "manifest_list"],
)
def test_malformed_journal_is_one_line_and_kept(tmp_path, capsys, fields):
    out = tmp_path / "out"
    out.mkdir()
    tmp = out / ".wirecheck-abc123.tmp"
    tmp.mkdir()
    (tmp / TAG).write_bytes(b"")
    _assert_refused(out, capsys, _journal(out, **fields))


@pytest.mark.parametrize("kind", ["fifo", "symlink", "hard_link", "not_json", "huge"])
def test_journal_that_is_no_regular_file_of_ours_is_refused(tmp_path, capsys, kind):
    out = tmp_path / "out"
    out.mkdir()
    elsewhere = tmp_path / "elsewhere.json"
    elsewhere.write_text(json.dumps({"wirecheck_journal": 1}))
    path = out / JOURNAL
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "symlink":
        os.symlink(elsewhere, path)
    elif kind == "hard_link":
        os.link(elsewhere, path)
    elif kind == "not_json":
        path.write_bytes(b"\xff\xfe not json")
    else:
        with open(path, "wb") as fh:
            fh.truncate(2 << 20)
    before = os.lstat(path)
    rc, err = _render(out, capsys)
    assert rc == 2 and err.count("\n") == 1 and JOURNAL in err, err
    after = os.lstat(path)
    assert (after.st_ino, after.st_mode, after.st_size) == (before.st_ino, before.st_mode, before.st_size)
    assert elsewhere.read_text() == json.dumps({"wirecheck_journal": 1})
