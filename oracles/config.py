"""``[tool.wirecheck]`` in a project's ``pyproject.toml``: settings shared by crosscheck and the pytest plugin.

::

    [tool.wirecheck]
    candidate = "src/myproj/projection.py:project"  # crosscheck --candidate; the fixture's default projector
    # candidate-cmd = "./build/projector --flag"   # or a program (crosscheck --candidate-cmd; docs/protocol.md)
    # candidate-timeout = 10                      # seconds per request to either
    # candidate-precision = "float32"             # what it computes in (default: from the dtype it returns)
    scenes = ["cube", "tests/arm.scene"]   # built-in or example names, or paths relative to this file
    cases = ["on_axis", "near_plane"]      # a subset of oracles.cases.CASE_NAMES
    frames = 8                             # frames of the motion per case
    level = "vertices"                     # or "pixels" (OpenCV and pyrender); or oracles = ["opencv"]
    tol-px = 0.01                          # and min-f1, min-f1-0px: the crosscheck options of that name
    spin = [1, 1, 0]                       # full turns about X, Y, Z over the frames

Keys are crosscheck's option names. An explicit setting wins over this table
(a command-line option, a keyword of the fixture's call), and the table over
the built-in defaults. The table is read from the nearest ``pyproject.toml``
at or above the working directory (crosscheck) or pytest's rootdir (the
plugin); a ``pyproject.toml`` without the table means no settings.

Every value is checked when the file is read: an unknown key, a wrong type,
or a setting that selects nothing (no scenes, no cases, zero frames) is an
:class:`~wirecheck.core.errors.InputError` naming the file, the key and the
value, never a run that compares nothing.
"""

from __future__ import annotations

import difflib
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

from wirecheck.core.errors import InputError
from wirecheck.core.limits import MAX_CANDIDATE_TIMEOUT_S
from wirecheck.core.user_files import RefusedFile, problem, read_text

from .tolerances import PRECISIONS

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

TABLE = "tool.wirecheck"

#: The keys and what each must be (said in the error message).
KEYS = {
    "candidate": "a string FILE.py:FUNC or MODULE:FUNC",
    "candidate-cmd": "a non-empty command string (a program speaking docs/protocol.md)",
    "candidate-timeout": "a number of seconds > 0 and at most 86400 (one day)",
    "candidate-precision": "'float32' or 'float64'",
    "scenes": "a non-empty list of scene names or paths",
    "cases": "a non-empty list of case names",
    "frames": "an integer >= 1",
    "level": "'vertices' or 'pixels'",
    "oracles": "a list of 'opencv' and 'pyrender' with 'opencv' among them",
    "tol-px": "a number >= 0",
    "min-f1": "a number in [0, 1]",
    "min-f1-0px": "a number in [0, 1]",
    "spin": "a list of three finite numbers [X, Y, Z]",
}

#: Keyword of oracles.api.check_projector for each key (``level``/``oracles`` become ``oracles``).
API_KEYWORDS = {
    "scenes": "scenes",
    "cases": "cases",
    "frames": "frames",
    "tol-px": "tol_px",
    "min-f1": "min_f1",
    "min-f1-0px": "min_f1_0px",
    "spin": "turns",
    "candidate-timeout": "timeout_s",
    "candidate-precision": "precision",
}


@dataclass(frozen=True)
class Config:
    """Validated settings from one file; ``values`` holds only the keys the file sets.

    Paths (``scenes`` entries that are files, a ``candidate`` FILE.py) are
    absolute, resolved against the file's folder; ``level`` is set for either
    ``level`` or ``oracles``.
    """

    path: Path | None = None
    values: dict = field(default_factory=dict)

    def api_kwargs(self) -> dict:
        """The settings as keywords of :func:`wirecheck.oracles.api.check_projector`."""
        kwargs = {API_KEYWORDS[k]: v for k, v in self.values.items() if k in API_KEYWORDS}
        if "level" in self.values:
            # only here: every pytest start calls this (the plugin), and the runner costs ~0.7 s to import
            from .runner import LEVEL_ORACLES

            kwargs["oracles"] = LEVEL_ORACLES[self.values["level"]]
        return kwargs


def _absolute(path: Path) -> str:
    """``path`` resolved (links followed); only made absolute where it cannot be (a link loop: Python 3.11 raises
    RuntimeError), so that the reader of the file names the loop in its one line."""
    try:
        return str(path.resolve())
    except (RuntimeError, OSError):
        return os.path.abspath(path)


def find_pyproject(start: Path) -> Path | None:
    """The nearest ``pyproject.toml`` at or above ``start``; None when there is none."""
    start = Path(start).resolve()
    for folder in (start, *start.parents):
        candidate = folder / "pyproject.toml"
        if candidate.exists():  # a FIFO or folder of that name is refused by load_config, not passed over
            return candidate
    return None


def load_config(path: Path | None = None, start: Path | None = None) -> Config:
    """Read and validate ``[tool.wirecheck]``.

    ``path`` is a file named by the user (it must exist and hold the table);
    without it the nearest ``pyproject.toml`` at or above ``start`` (default:
    the working directory) is read, and no file or no table means no settings.
    """
    explicit = path is not None
    path = Path(path) if explicit else find_pyproject(Path.cwd() if start is None else start)
    if path is None:
        return Config()
    try:
        # a UTF-8 byte-order mark (Windows editors) is not TOML: tomllib's message for it is
        # "Invalid statement (at line 1, column 1)", which points nowhere useful
        data = tomllib.loads(read_text(path, "config"))
    except RefusedFile as exc:
        if exc.problem == "missing":
            raise InputError(f"{path}: file not found: expected a pyproject.toml with a [{TABLE}] table") from None
        raise
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses per nested array or inline table
        raise InputError(
            f"{path}: not valid TOML here: arrays or tables nested too deep for the "
            "reader: expected the settings of docs (a few levels at most)"
        ) from None
    table = data.get("tool", {}).get("wirecheck") if isinstance(data.get("tool"), dict) else None
    if table is None:
        if explicit:
            raise InputError(f"{path}: no [{TABLE}] table: expected the settings there")
        return Config(path=path)
    if not isinstance(table, dict):
        raise InputError(f"{path}: {TABLE} = {table!r}: expected a table [{TABLE}]")
    return Config(path=path, values=validate(table, path))


def validate(table: dict, path: Path) -> dict:
    """The table's values checked against :data:`KEYS`, paths made absolute; InputError otherwise."""
    from wirecheck.core.scene.files import MESH_SUFFIXES, builtin_names, example_names

    from .cases import ALL_CASE_NAMES as CASE_NAMES

    def bad(key, value, expected=None):
        return InputError(f"{path}: [{TABLE}] {key} = {value!r}: expected {expected or KEYS[key]}")

    def number(value) -> bool:
        return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)

    def strings(value) -> bool:
        return isinstance(value, list) and bool(value) and all(isinstance(v, str) and v.strip() for v in value)

    out = {}
    base = path.parent
    for key, value in table.items():
        if key not in KEYS:
            close = difflib.get_close_matches(key, KEYS, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise InputError(f"{path}: [{TABLE}] unknown key {key!r}{hint}: expected some of {', '.join(KEYS)}")
        if "\x00" in (
            value
            if isinstance(value, str)
            else "".join(v for v in value if isinstance(v, str))
            if isinstance(value, list)
            else ""
        ):
            raise bad(key, value, "text without a NUL character (no file name or command holds one)")
        if key == "candidate":
            if not isinstance(value, str) or ":" not in value:
                raise bad(key, value)
            target, func = value.rsplit(":", 1)
            if target.endswith(".py") or "/" in target:
                target = _absolute(base / target)
            out[key] = f"{target}:{func}"
        elif key == "candidate-cmd":
            if not (isinstance(value, str) and value.strip()):
                raise bad(key, value)
            out[key] = value
        elif key == "candidate-timeout":
            if not (number(value) and 0 < value <= MAX_CANDIDATE_TIMEOUT_S):
                raise bad(key, value)
            out[key] = float(value)
        elif key == "candidate-precision":
            if value not in PRECISIONS:
                raise bad(key, value)
            out[key] = value
        elif key == "scenes":
            if not strings(value):
                raise bad(key, value)
            known = set(builtin_names()) | set(example_names())
            scenes = []
            for name in value:
                if "/" in name or "\\" in name or Path(name).suffix:
                    scene_path = base / name
                    refused = problem(scene_path, "mesh" if scene_path.suffix.lower() in MESH_SUFFIXES else "scene")
                    if refused is not None:  # before resolve(): a link loop is named, not a RuntimeError
                        raise bad(key, value, f"existing scene files: {str(scene_path)!r} is not a file ({refused})")
                    scenes.append(_absolute(scene_path))
                elif name in known:
                    scenes.append(name)
                else:
                    raise bad(
                        key,
                        value,
                        f"built-in or example scenes ({', '.join(sorted(known))}) or paths: {name!r} is neither",
                    )
            out[key] = scenes
        elif key == "cases":
            unknown = [c for c in value if c not in CASE_NAMES] if strings(value) else None
            if unknown is None or unknown:
                raise bad(
                    key,
                    value,
                    f"a non-empty list of some of {', '.join(CASE_NAMES)}"
                    + (f" ({', '.join(map(repr, unknown))} unknown)" if unknown else ""),
                )
            out[key] = list(value)
        elif key == "frames":
            if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
                raise bad(key, value)
            out[key] = value
        elif key in ("level", "oracles"):
            from .runner import LEVELS, level_for_oracles

            if "level" in out:
                raise InputError(f"{path}: [{TABLE}] both level and oracles: expected one of them")
            if key == "level":
                if value not in LEVELS:
                    raise bad(key, value)
                out["level"] = value
            else:
                try:
                    out["level"] = level_for_oracles(value) if strings(value) else None
                except ValueError:
                    out["level"] = None
                if out["level"] is None:
                    raise bad(key, value)
        elif key == "tol-px":
            if not (number(value) and value >= 0):
                raise bad(key, value)
            out[key] = float(value)
        elif key in ("min-f1", "min-f1-0px"):
            if not (number(value) and 0 <= value <= 1):
                raise bad(key, value)
            out[key] = float(value)
        elif key == "spin":
            if not (isinstance(value, list) and len(value) == 3 and all(number(v) for v in value)):
                raise bad(key, value)
            out[key] = tuple(float(v) for v in value)
    if "candidate" in out and "candidate-cmd" in out:
        raise InputError(f"{path}: [{TABLE}] both candidate and candidate-cmd: expected one of them")
    return out


#: crosscheck's argparse destination for each key.
CLI_DESTS = {
    "candidate": "candidate",
    "candidate-cmd": "candidate_cmd",
    "candidate-timeout": "candidate_timeout",
    "candidate-precision": "candidate_precision",
    "scenes": "scene",
    "cases": "cases",
    "frames": "frames",
    "level": "level",
    "tol-px": "tol_px",
    "min-f1": "min_f1",
    "min-f1-0px": "min_f1_0px",
    "spin": "spin",
}


def _cli_value(key: str, value):
    """A validated value as crosscheck's parser would have produced it from the command line."""
    if key == "cases":
        return ",".join(value)
    if key == "spin":
        return ",".join(repr(v) for v in value)
    return value


def trust_line(path: Path, key: str, value: str) -> str:
    """The stderr line said before crosscheck runs a candidate that a settings file chose (docs/pytest.md).

    A ``[tool.wirecheck]`` table is trusted as pytest trusts a ``conftest.py``:
    running crosscheck in a folder runs the program its nearest pyproject.toml
    names. The line names the file and the program before it starts, so a
    table the user did not write is seen, not silently obeyed.
    """
    from .datasets.dataset import printable

    what = "program" if key == "candidate-cmd" else "Python candidate (its file is imported and run)"
    return (
        f"crosscheck: {printable(str(path))} [{TABLE}] chose the {what}: {key} = {printable(repr(value))}; "
        "it runs now with your permissions (as pytest runs a conftest.py): give --candidate, --candidate-cmd "
        "or --config FILE to choose otherwise"
    )


class _Unset:
    """Marks an option the command line did not give (argparse keeps a namespace's existing values)."""


def parse_cli(parser, argv=None):
    """crosscheck's arguments over ``[tool.wirecheck]``: ``(args, config, keys_applied)``.

    An option given on the command line wins, then the table (``--config FILE``,
    default the nearest pyproject.toml), then the parser's default. ``--suite``
    uses none of the table (its cases are fixed), ``--sweep`` not its
    candidate (the sweep runs core), and ``--level``/``--oracles`` on the
    command line replace its ``level``/``oracles``. Raises InputError for a
    bad table; argparse exits 2 for bad options.
    """
    import argparse

    unset = _Unset()
    dests = [d for d in (*CLI_DESTS.values(), "oracles") if d != "scene"]  # append actions need a list
    args = parser.parse_args(argv, namespace=argparse.Namespace(**{d: unset for d in dests}))
    given = {d for d in dests if getattr(args, d) is not unset} | ({"scene"} if args.scene is not None else set())
    for d in dests:
        if d not in given:
            setattr(args, d, parser.get_default(d))
    config = load_config(Path(args.config) if args.config else None)
    applied = []
    if args.suite:
        return args, config, applied
    for key, value in config.values.items():
        dest = CLI_DESTS[key]
        picked = key in ("candidate", "candidate-cmd") and (args.sweep or {"candidate", "candidate_cmd"} & given)
        if dest in given or (key == "level" and "oracles" in given) or picked:
            continue  # a candidate on the command line replaces the table's, of either kind
        setattr(args, dest, _cli_value(key, value))
        applied.append(key)
    return args, config, applied


def settings_for(given: dict, config, defaults: dict) -> dict:
    """The public API's settings: ``given`` (a ``check_*`` function's keywords, None = not given) over
    ``[tool.wirecheck]`` (``config``: a file, None = the nearest pyproject.toml, False = none) over ``defaults``.

    Every ``check_*`` function reads the table this way (oracles.api, oracles.frames_api,
    oracles.unprojector_api): the keys of :data:`API_KEYWORDS` that are among ``given``, plus the table's
    ``candidate`` and ``candidate_cmd`` (the projector's, read by oracles.api alone). Raises InputError
    (a ValueError) for a bad table, naming the file, the key and the value.
    """
    table: dict = {}
    if config is not False:
        loaded = load_config(Path(config) if config is not None else None)
        table = {k: v for k, v in loaded.api_kwargs().items() if k in given}
        table["candidate"] = loaded.values.get("candidate")
        table["candidate_cmd"] = loaded.values.get("candidate-cmd")
    out = {**defaults, **{k: v for k, v in table.items() if v is not None}}
    out.update({k: v for k, v in given.items() if v is not None})
    return out
