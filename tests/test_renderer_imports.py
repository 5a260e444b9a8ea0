"""What the renderer process loads: the seed command's start-up cost is mostly imports (issue 12).

Each check runs in a fresh interpreter (``sys.modules`` of this test process is
whatever the earlier tests imported) and fails when someone adds back an
import the renderer's PNG path does not need. Speed itself is measured in
benchmarks/bench_seed.py, not here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

#: Modules a PNG run of ``renderer`` must not load, and what each would cost:
#: oracles and their libraries (OpenCV, pyrender, scipy, trimesh: scene files
#: only), plotting (--plots), Pillow (only for frames that are not bilevel),
#: animations (av, tqdm: a bar only on a terminal), importlib.metadata (--version
#: only; ~25 ms), numpy.ma (np.unique imports it; ~15 ms).
NOT_LOADED = (
    "wirecheck.oracles",
    "cv2",
    "pyrender",
    "scipy",
    "trimesh",
    "matplotlib",
    "PIL",
    "av",
    "tqdm",
    "importlib.metadata",
    "numpy.ma",
)


def _fresh(code: str, tmp_path) -> dict:
    """Run ``code`` in a new interpreter without OPENBLAS_NUM_THREADS; the JSON it prints last."""
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_png_run_loads_none_of_the_optional_libraries(tmp_path):
    got = _fresh(
        "import json, sys\n"
        "from wirecheck.core.app.cli import main\n"
        "status = main(['--scene', 'cube', '--frames', '4', '--out', 'out'])\n"
        "print(json.dumps({'status': status, 'modules': sorted(sys.modules)}))\n",
        tmp_path,
    )
    assert got["status"] == 0
    assert len(list((tmp_path / "out" / "cube-frames").glob("frame_*.png"))) == 4  # it did render and write
    loaded = [m for m in got["modules"] if any(m == name or m.startswith(name + ".") for name in NOT_LOADED)]
    assert loaded == []
    assert "numpy" in got["modules"]  # the check sees the modules of the run (not an empty list)


@pytest.mark.skipif(
    (os.cpu_count() or 1) < 2 or not os.path.isdir("/proc/self/task"),
    reason="OpenBLAS starts no worker threads on one CPU; threads counted in /proc (Linux)",
)
def test_the_cli_loads_numpy_with_one_blas_thread_and_leaves_the_environment_as_it_was(tmp_path):
    count = (
        "import json, os\n{}\n"
        "print(json.dumps({{'threads': len(os.listdir('/proc/self/task')), "
        "'env': os.environ.get('OPENBLAS_NUM_THREADS')}}))\n"
    )
    plain = _fresh(count.format("import numpy"), tmp_path)
    cli = _fresh(count.format("import wirecheck.core.app.cli"), tmp_path)
    assert plain["threads"] > 1  # numpy alone starts OpenBLAS workers here: the check can fail
    assert cli == {"threads": 1, "env": None}  # none with the CLI, and no variable left for child processes
