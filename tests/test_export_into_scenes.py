"""``crosscheck export DIR`` with DIR in the bundled ``scenes/`` folder is refused as ``--out`` and ``--report-dir``
there are (issue 36): a job there (its ``scenes/cube.obj``, README) would pass for scenes in later runs."""

import hashlib
import os
import shutil

import pytest
from wirecheck.core.scene.files import SCENE_DIR
from wirecheck.oracles import cli as crosscheck_cli


def _tree(folder):
    """Every path under ``folder`` with the SHA-256 of each file."""
    out = {}
    for dirpath, _, files in os.walk(folder):
        for name in files:
            path = os.path.join(dirpath, name)
            with open(path, "rb") as fh:
                out[os.path.relpath(path, folder)] = hashlib.sha256(fh.read()).hexdigest()
    return out


@pytest.fixture
def job_name():
    name = f"wirecheck-test-export-{os.getpid()}"
    yield name
    for folder in (SCENE_DIR, SCENE_DIR / "examples"):  # before the fix the job was written there: remove it
        shutil.rmtree(folder / name, ignore_errors=True)


@pytest.mark.parametrize("where", ["scenes", "scenes/examples", "a link to scenes"])
def test_export_into_the_bundled_scenes_is_refused(tmp_path, capsys, job_name, where):
    if where == "a link to scenes":
        (tmp_path / "link").symlink_to(SCENE_DIR)
        target = tmp_path / "link" / job_name
    else:
        target = SCENE_DIR.parent / where / job_name
    before = _tree(SCENE_DIR)
    rc = crosscheck_cli.main(["export", str(target), "--scene", "cube", "--cases", "on_axis", "--frames", "1"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1, err
    assert err == (
        f"crosscheck: error: export DIR {str(target)!r} is inside the scenes folder {str(SCENE_DIR)!r}: "
        "expected a job folder elsewhere (e.g. job/)\n"
    )
    assert _tree(SCENE_DIR) == before
