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
    assert (report["summary"]["passed"], report["summary"]["cases"]) == (2, 14)  # 7 cameras each, both loaded
    md = (out / "report.md").read_text(encoding="utf-8")
    assert "bad\\xff.obj" in md and "dir\\xfd/y.obj" in md


def test_two_inputs_naming_one_mesh_name_it_printably(tmp_path, capsys):
    # The same folder twice: one error line; its paths escaped too (a surrogate in an error line
    # is not text either).
    data = tmp_path / "data"
    data.mkdir()
    _bytes_path(data, b"bad\xff.obj")
    code = cli.main(
        [
            "--report-dir",
            str(tmp_path / "run"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--scene",
            str(data),
            "--scene",
            str(data),
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "two meshes named" in err
    assert "bad\\xff.obj" in err and "\udcff" not in err
    assert not (tmp_path / "run").exists()


def _error_line(capsys, argv) -> str:
    code = cli.main(argv)
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, (code, err)
    return err


@pytest.mark.parametrize(
    "extra, message",
    [
        # a local Dask cluster of 99999 workers never started (killed after 200 s, a RuntimeError from
        # distributed on the way)
        (["--executor", "dask", "--jobs", "99999"], "--jobs 99999: expected at most 256 worker processes"),
        (["--jobs", "257"], "--jobs 257: expected at most 256 worker processes"),
        # 1e308 s: waited for ever on an address where nothing listens
        (
            ["--scheduler", "tcp://127.0.0.1:1", "--scheduler-timeout", "1e308"],
            "--scheduler-timeout 1e+308: expected a number of seconds > 0 and <= 3600",
        ),
    ],
)
def test_executor_bounds(tmp_path, capsys, extra, message):
    err = _error_line(
        capsys,
        [
            "--report-dir",
            str(tmp_path / "run"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            *extra,
        ],
    )
    assert message in err and not (tmp_path / "run").exists()


def test_tls_scheduler_without_certificates_is_an_input_error(tmp_path, capsys):
    # tls:// passes the address check; distributed then raised a TypeError (no ssl_context), reported
    # as "a Dask task failed ... every worker needs the same wirecheck": not the cause.
    pytest.importorskip("distributed")
    err = _error_line(
        capsys,
        [
            "--report-dir",
            str(tmp_path / "run"),
            "--level",
            "vertices",
            "--frames",
            "1",
            "--scene",
            "cube",
            "--cases",
            "on_axis",
            "--scheduler",
            "tls://127.0.0.1:1",
            "--scheduler-timeout",
            "1",
        ],
    )
    assert "--scheduler tls://127.0.0.1:1: TLS without certificates" in err and "Dask task failed" not in err
    assert not (tmp_path / "run").exists()


def test_local_dask_cluster_starts_no_more_workers_than_tasks(monkeypatch):
    # --executor dask --jobs 8 for 1 task: 1 worker process, as the local process pool does.
    from wirecheck.oracles import executors

    seen = {}

    class Stop(Exception):
        pass

    def fake_client(spec, n_workers=None):
        seen["n_workers"] = n_workers
        raise Stop

    monkeypatch.setattr(executors, "_dask_client", fake_client)
    with pytest.raises(Stop):
        with executors.open_executor(executors.ExecutorSpec(kind="dask", jobs=8), n_tasks=1):
            pass
    assert seen == {"n_workers": 1}
