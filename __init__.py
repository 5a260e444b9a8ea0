"""wirecheck: a from-scratch wireframe projector, and a harness that proves projection code right.

The public API, importable from the top level::

    from wirecheck import assert_projector

    def test_my_projector():
        assert_projector(my_project)   # my_project(p_world (N, 3), camera) -> p_px (N, 2)

- :func:`check_projector` / :func:`assert_projector`: crosscheck a projector
  against OpenCV (vertices) and pyrender (pixels).
- :func:`check_frames` / :func:`assert_frames`: judge a renderer's own frames of a
  job written by ``crosscheck export`` (``crosscheck --candidate-frames``).
- :func:`check_unprojector` / :func:`assert_unprojector`: the way back, an
  unprojector from pixels and depth along ``forward`` to world points, against the
  exact inverse of the conventions.
- :class:`Camera`, :func:`look_at`, :func:`camera_z`: the camera (conventions in
  :mod:`wirecheck.core.conventions`).
- :func:`load_scene`, :class:`Scene`, :class:`Motion`: scenes and their motion.
- :func:`project_points`, :func:`render_frame`, :class:`Frame`: core's projector
  and one frame of its pipeline.
- :class:`SceneRenderer`: frame ``k`` of a scene's motion, as ``renderer``
  draws it (one static object or several moving ones).

In the source tree this file is the repository root's ``__init__.py``;
``wirecheck.core``, ``wirecheck.oracles`` and ``wirecheck.scenes`` are the
folders ``core/``, ``oracles/`` and ``scenes/`` (``pyproject.toml`` maps them).
"""

from importlib import import_module
from typing import Any

# Names are imported on first use (PEP 562), so ``import wirecheck.core`` (the
# renderer) never pays for the oracles' imports (OpenCV, scipy).
_EXPORTS = {
    "Camera": "core.camera",
    "camera_z": "core.camera",
    "look_at": "core.camera",
    "InputError": "core.errors",
    "Frame": "core.projector.pipeline",
    "render_frame": "core.projector.pipeline",
    "project_points": "core.projector.projection",
    "SceneRenderer": "core.scene.frames",
    "Scene": "core.scene.model",
    "load_scene": "core.scene.files",
    "Motion": "core.transforms",
    "assert_projector": "oracles.api",
    "check_projector": "oracles.api",
    "assert_frames": "oracles.frames_api",
    "check_frames": "oracles.frames_api",
    "assert_unprojector": "oracles.unprojector_api",
    "check_unprojector": "oracles.unprojector_api",
}

__all__ = ["__version__", *sorted(_EXPORTS)]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("wirecheck")
    except PackageNotFoundError:  # a source tree that was never installed
        return "0+unknown"


def __getattr__(name: str) -> Any:
    if name == "__version__":  # importlib.metadata costs ~40 ms: only when asked
        globals()[name] = _version()
        return globals()[name]
    if name in _EXPORTS:
        value = getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'wirecheck' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
