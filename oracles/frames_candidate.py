"""``crosscheck --candidate-frames DIR``: judge a renderer by its own frames.

``DIR`` is a job written by :mod:`oracles.export` with the renderer's PNGs
under ``frames/``. Each frame is compared with pyrender's rendering (the
oracle the verdict rests on, as in the pixel level of crosscheck) and with
core's, both drawn from the job's own files (OBJ vertices, the frame's
camera and model matrix), by edge-pixel F1 at 0 and 1 px
(:func:`oracles.metrics.pixel_scores`). The case's frames are then diagnosed
from the images alone (:mod:`oracles.image_diagnose`).

A gate never passes on nothing: the job must list cases and frames, every
listed frame must be there at its camera's size and readable, and a PNG under
``frames/`` that the job does not list is refused too (frames of another
job). Each problem is one line of :class:`FramesError` (exit 2).
"""

from __future__ import annotations

import json
import os
import stat
import time
import warnings
from pathlib import Path

import numpy as np

from wirecheck.core.errors import InputError

from . import metrics
from .export import JOB_KIND, JOB_VERSION, frame_name

#: Problem lines shown before "... and N more".
MAX_LINES = 20
#: Entries walked under ``frames/`` before the walk stops: a job lists at most
#: MAX_FRAMES frames per case, and links between folders must not make the walk unbounded.
MAX_WALK = 200_000


class FramesError(InputError):
    """The job or its frames cannot be judged: one line per problem."""

    def __init__(self, problems: list[str]):
        self.problems = problems
        shown = problems[:MAX_LINES]
        more = len(problems) - len(shown)
        super().__init__("\n".join(shown + ([f"... and {more} more"] if more else [])))

    def __str__(self) -> str:       # one line per problem, kept apart (InputError joins lines into one)
        return Exception.__str__(self)


def file_problem(path: Path) -> str | None:
    """Why ``path`` is not a regular file to read, in a phrase (``"missing"``, ``"a FIFO"``, ...); None if it is one.

    Checked before any open: opening a FIFO named like a job's file would block
    the run forever, and a folder or device is no file of a job.
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return "a broken link" if os.path.islink(path) else "missing"
    except OSError as exc:          # a link loop, a name too long
        return f"unreadable ({exc.strerror or exc})"
    if stat.S_ISREG(mode):
        return None
    kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else
            "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else
            "not a file")
    return f"{kind}, not a regular file"


def _no_duplicate_keys(pairs: list) -> dict:
    """``json.loads``' object hook: a key given twice is a ValueError (JSON keeps the last one, silently)."""
    out = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"key {key!r} given twice")
        out[key] = value
    return out


def read_json(path: Path):
    """The JSON of a job file (UTF-8, a BOM allowed); ValueError for a key given twice."""
    return json.loads(Path(path).read_text(encoding="utf-8-sig"), object_pairs_hook=_no_duplicate_keys)


def load_job(job_dir: Path) -> dict:
    """The manifest ``DIR/job.json``, checked; FramesError otherwise."""
    path = Path(job_dir) / "job.json"
    if not Path(job_dir).is_dir():
        raise FramesError([f"--candidate-frames {str(job_dir)!r}: not a directory: expected a job folder "
                           "written by 'crosscheck export'"])
    problem = file_problem(path)
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected a job folder written by 'crosscheck export'"])
    try:
        job = read_json(path)
    except (OSError, ValueError, RecursionError) as exc:        # RecursionError: arrays nested 100,000 deep
        raise FramesError([f"{path}: unreadable ({exc}): expected the JSON 'crosscheck export' wrote"]) from None
    if not isinstance(job, dict) or job.get("kind") != JOB_KIND:
        raise FramesError([f"{path}: not a wirecheck frames job (kind {job.get('kind') if isinstance(job, dict) else None!r})"])
    if job.get("version") != JOB_VERSION:
        raise FramesError([f"{path}: job version {job.get('version')!r}: expected {JOB_VERSION} (export it again)"])
    if not job.get("cases"):
        raise FramesError([f"{path}: the job lists no frames: nothing to judge"])
    problem = _job_problem(job)
    if problem is not None:
        raise FramesError([f"{path}: {problem} (export the job again)"])
    return job


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _job_problem(job: dict) -> str | None:
    """What in a job.json is not as ``crosscheck export`` writes it, in one phrase; None when all is.

    A job is hand-editable JSON: every field the judging reads is checked here,
    so that an edited or damaged one is a usage error naming the field, never a
    crash later or numbers in the report that mean nothing.
    """
    from wirecheck.core.limits import MAX_FRAMES, check_image_size
    from wirecheck.core.scene_files import NAME_PATTERN

    frames, every = job.get("frames"), job.get("every")
    if not (_is_int(frames) and 1 <= frames <= MAX_FRAMES):
        return f"frames {frames!r}: expected an integer in 1..{MAX_FRAMES}"
    if not (_is_int(every) and 1 <= every <= frames):
        return f"every {every!r}: expected an integer in 1..frames ({frames})"
    checked = list(range(1, frames + 1, every))
    if job.get("frame_numbers") != checked:
        return f"frame_numbers {str(job.get('frame_numbers'))[:60]}: expected 1, 1+every, ... up to frames"
    turns = (job.get("motion") or {}).get("turns") if isinstance(job.get("motion"), dict) else None
    if not (isinstance(turns, list) and len(turns) == 3
            and all(isinstance(t, (int, float)) and not isinstance(t, bool) and np.isfinite(t) for t in turns)):
        return f"motion.turns {turns!r}: expected three finite numbers"
    if job.get("style") != "wireframe":
        return f"style {job.get('style')!r}: expected 'wireframe' (the frames judged are wireframes)"
    scenes, cases = job.get("scenes"), job.get("cases")
    if not (isinstance(scenes, list) and scenes and all(isinstance(r, dict) for r in scenes)):
        return "scenes: expected a list of the job's scenes"
    names = set()
    for r in scenes:
        name, obj = r.get("name"), r.get("obj")
        if not (isinstance(name, str) and NAME_PATTERN.fullmatch(name)) or name in names:
            return f"scene name {name!r}: expected a name of letters, digits, '_', '.', '-', each scene once"
        names.add(name)
        expected = {"model": f"scenes/{name}.obj", "world per frame": f"scenes/{name}/frame_NNNN.obj"}
        if expected.get(r.get("space")) != obj:
            return (f"scene {name!r}: space {r.get('space')!r}, obj {obj!r}: expected space 'model' with "
                    f"obj {expected['model']!r}, or 'world per frame' with {expected['world per frame']!r}")
        if r.get("space") == "model" and not all(_is_int(r.get(k)) and r[k] >= 0 for k in ("vertices", "edges")):
            return f"scene {name!r}: vertices {r.get('vertices')!r}, edges {r.get('edges')!r}: expected counts"
    if not (isinstance(cases, list) and all(isinstance(c, dict) for c in cases)):
        return "cases: expected a list of the job's cases"
    pairs = set()
    for c in cases:
        scene, case, w, h = c.get("scene"), c.get("case"), c.get("width"), c.get("height")
        if scene not in names or not (isinstance(case, str) and NAME_PATTERN.fullmatch(case)):
            return f"case {scene!r} / {case!r}: expected a scene of 'scenes' and a case name"
        if (scene, case) in pairs:      # judged twice, it would count twice in the summary
            return f"case {scene} / {case}: listed twice: expected each case once"
        pairs.add((scene, case))
        if not (_is_int(w) and _is_int(h)):
            return f"case {scene} / {case}: width {w!r}, height {h!r}: expected integers"
        try:
            check_image_size(w, h, f"case {scene} / {case}: width x height")
        except InputError as exc:
            return str(exc)
        listed = [f"frames/{scene}/{case}/{frame_name(k, 'png')}" for k in checked]
        if c.get("frames") != listed:
            return (f"case {scene} / {case}: frames {str(c.get('frames'))[:80]}: expected "
                    f"frames/{scene}/{case}/frame_NNNN.png for each of frame_numbers")
    return None


class FrameProblem(ValueError):
    """A frame file that is not an image the job asked for: the reason, in a phrase."""


#: 16-bit grey samples at or above this are drawn: a high byte of 128 or more, as Pillow reads
#: 16-bit RGB(A) (by its high byte), so every 16-bit colour type reads alike; an 8-bit value x
#: is 257 x in 16 bits, whose high byte is x: 8- and 16-bit copies of one image read the same.
THRESHOLD_16 = 128 << 8


def read_png(path: Path, width: int, height: int) -> np.ndarray:
    """``(H, W)`` bool: drawn where the luminance over the rule's black background is >= 128 (:func:`read_grey`)."""
    return read_grey(path, width, height) >= 128


def read_grey(path: Path, width: int, height: int) -> np.ndarray:
    """``(H, W)`` uint8: each pixel's luminance over the rule's black background, rounded down.

    One still PNG of the camera's size is expected; anything else is a
    :class:`FrameProblem`. A pixel's luminance is Pillow's (ITU-R 601-2) of its
    RGB, times its alpha (``A / 255``; palette transparency included): the
    pixel as it shows over black, so a transparent pixel is never drawn. 16-bit
    grey is read by its high byte (:data:`THRESHOLD_16`). Rounded down, a value
    is >= 128 exactly where the unrounded one is: the drawn pixels of the rule.
    The grey levels are the coverage of antialiased lines (:mod:`oracles.line_style`).
    The size is checked before any pixel is decoded (a huge image costs nothing).
    """
    from PIL import Image

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)     # the size is checked next
        with Image.open(path) as im:
            if im.format != "PNG":
                raise FrameProblem(f"a {im.format} image: expected a PNG")
            if getattr(im, "n_frames", 1) != 1:
                raise FrameProblem(f"an animated PNG of {im.n_frames} frames: expected one still image")
            if im.size != (width, height):
                raise FrameProblem(f"size {im.size[0]}x{im.size[1]}: expected {width}x{height} (the camera's)")
            im.load()
            if im.mode in ("I", "I;16", "I;16B", "I;16L"):          # 16-bit grey: its high byte
                return (np.clip(np.asarray(im, dtype=np.int64), 0, 65535) >> 8).astype(np.uint8)
            if not (im.mode in ("RGBA", "LA", "PA", "RGBa", "La") or "transparency" in im.info):   # opaque
                grey = im if im.mode == "L" else im.convert("RGB").convert("L")   # L, the usual: as it is
                return np.array(grey, dtype=np.uint8)
            rgba = im.convert("RGBA")
            grey = np.asarray(rgba.convert("RGB").convert("L"), dtype=np.uint16)
            alpha = np.asarray(rgba.getchannel("A"), dtype=np.uint16)
    return (grey * alpha // 255).astype(np.uint8)      # exact (at most 255 * 255 < 2**16); >= 128 iff grey * alpha >= 128 * 255


def _walk(frames_dir: Path) -> list[Path]:
    """Every entry under ``frames_dir`` that is not a folder; links to folders followed, a link loop is not.

    A folder is not entered again below itself (a loop); the walk stops with a
    FramesError past :data:`MAX_WALK` entries. A folder that cannot be listed
    is skipped: its listed frames are reported one by one.
    """
    out, n = [], 0
    stack = [(frames_dir, frozenset())]
    while stack:
        folder, above = stack.pop()
        try:
            st = folder.stat()
            key = (st.st_dev, st.st_ino)
            if key in above:
                continue
            with os.scandir(folder) as it:
                items = sorted(it, key=lambda e: e.name)
        except OSError:
            continue
        for item in items:
            n += 1
            if n > MAX_WALK:
                raise FramesError([f"{frames_dir}: more than {MAX_WALK:,} files and folders: expected the "
                                   "job's frames (frames/<scene>/<case>/frame_NNNN.png)"])
            try:
                is_dir = item.is_dir()
            except OSError:
                is_dir = False
            if is_dir:
                stack.append((Path(item.path), above | {key}))
            else:
                out.append(Path(item.path))
    return out


def load_frames(job_dir: Path, job: dict) -> dict:
    """Every listed frame as a grey image (:func:`read_grey`): ``{(scene, case): [(k, image)]}``; FramesError listing
    every problem."""
    job_dir = Path(job_dir)
    frames_dir = job_dir / "frames"
    if not frames_dir.is_dir():
        problem = file_problem(frames_dir)
        raise FramesError([f"{frames_dir}: {problem or 'a file, not a folder'}: the renderer's frames go there "
                           "(frames/<scene>/<case>/frame_NNNN.png; see README.md)"])
    found = {p.relative_to(job_dir).as_posix() for p in _walk(frames_dir)}
    if not found:
        raise FramesError([f"{frames_dir}: empty: expected the renderer's frames "
                           "(frames/<scene>/<case>/frame_NNNN.png; see README.md)"])
    listed = {f for c in job["cases"] for f in c["frames"]}
    if not found & listed:
        example = sorted(found)[0]
        raise FramesError([f"{frames_dir}: none of its {len(found)} files is a frame of this job "
                           f"(e.g. {example}; expected e.g. {sorted(listed)[0]}): frames of another job?"])
    problems = [f"{job_dir / rel}: not a frame of this job (expected only the files job.json lists)"
                for rel in sorted(found - listed)]
    out = {}
    for c in job["cases"]:
        images = []
        for rel in c["frames"]:
            path = job_dir / rel
            k = int(Path(rel).stem.split("_")[-1])
            problem = file_problem(path)
            if problem is not None:
                problems.append(f"{path}: {problem} (frame {k} of {c['scene']} / {c['case']})")
                continue
            try:
                images.append((k, read_grey(path, c["width"], c["height"])))
            except FrameProblem as exc:
                problems.append(f"{path}: {exc}")
            except Exception as exc:       # Pillow's many ways to say "not an image"
                problems.append(f"{path}: unreadable as PNG ({type(exc).__name__}: {exc})")
        out[(c["scene"], c["case"])] = images
    if problems:
        raise FramesError(problems)
    return out


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The ``v`` and ``l`` records of an OBJ export wrote: ``(vertices (N, 3), edges (E, 2) 0-based)``.

    FramesError (file:line) for a record that is not as export writes it: 3
    finite coordinates, 2 indices of vertices before it.
    """
    verts, edges = [], []
    problem = file_problem(path)
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected the OBJ 'crosscheck export' wrote"])
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise FramesError([f"{path}: unreadable ({exc}): expected the OBJ 'crosscheck export' wrote"]) from None
    for lineno, line in enumerate(text.splitlines(), start=1):
        parts = line.split()
        try:
            if parts and parts[0] == "v":
                verts.append([float(x) for x in parts[1:]])
                if len(parts) != 4 or not np.all(np.isfinite(verts[-1])):
                    raise ValueError
            elif parts and parts[0] == "l":
                edges.append([int(x) - 1 for x in parts[1:]])
                if len(parts) != 3 or not all(0 <= i < len(verts) for i in edges[-1]):
                    raise ValueError
        except ValueError:
            raise FramesError([f"{path}:{lineno}: {line.strip()[:60]!r}: expected 'v X Y Z' (finite) or 'l I J' "
                               f"(1..{len(verts)}), as 'crosscheck export' wrote"]) from None
    return np.asarray(verts, dtype=np.float64).reshape(-1, 3), np.asarray(edges, dtype=np.intp).reshape(-1, 2)


def _frame_camera(path: Path):
    """``(camera, model_matrix (4, 4))`` of a frame's JSON; FramesError naming the file otherwise."""
    from wirecheck.core.camera import Camera

    problem = file_problem(path)
    if problem is not None:
        raise FramesError([f"{path}: {problem}: expected the camera 'crosscheck export' wrote"])
    try:
        cam_json = read_json(path)
        camera = Camera(**cam_json["camera"])
        m = np.asarray(cam_json["model_matrix"], dtype=np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError(f"model_matrix of shape {m.shape}: expected 4x4 finite numbers")
    except (OSError, ValueError, KeyError, TypeError, AttributeError, OverflowError, RecursionError) as exc:
        what = f"no {exc}" if isinstance(exc, KeyError) else str(exc)
        raise FramesError([f"{path}: unreadable ({type(exc).__name__}: {what}): expected the camera JSON "
                           "'crosscheck export' wrote"]) from None
    return camera, m


def frame_inputs(job_dir: Path, job: dict, scene: str, case: str, k: int):
    """``(p_model (N, 3), edges (E, 2), camera, model_matrix (4, 4))`` of one frame, from the job's files."""
    job_dir = Path(job_dir)
    row = next(s for s in job["scenes"] if s["name"] == scene)       # load_job checked it is there
    obj = job_dir / (row["obj"] if row["space"] == "model" else f"scenes/{scene}/{frame_name(k, 'obj')}")
    p_model, edges = read_obj(obj)
    if row["space"] == "model" and (len(p_model), len(edges)) != (row["vertices"], row["edges"]):
        raise FramesError([f"{obj}: {len(p_model)} vertices, {len(edges)} edges: expected {row['vertices']} and "
                           f"{row['edges']} (job.json's; the file was changed or cut short)"])
    path = job_dir / f"cameras/{scene}/{case}/{frame_name(k, 'json')}"
    camera, m = _frame_camera(path)
    c = next(c for c in job["cases"] if (c["scene"], c["case"]) == (scene, case))
    if (camera.width, camera.height) != (c["width"], c["height"]):     # the frames were read at the job's size
        size = f"{camera.width}x{camera.height}"
        raise FramesError([f"{path}: camera {size[:40]}{'...' if len(size) > 40 else ''}: expected "
                           f"{c['width']}x{c['height']} "
                           f"(job.json's size of {scene} / {case}; export the job again)"])
    return p_model, edges, camera, m


def _min_scores(scores: list[dict], prefix: str = "") -> dict:
    keys = ("f1_0px", "f1_1px", "precision_0px", "recall_0px", "precision_1px", "recall_1px")
    return {f"{prefix}{k}": float(min(s[k] for s in scores)) for k in keys}


def judge_case(job_dir, job, scene: str, case: str, images: list, oracles, tol, diagnose: bool = True,
               line_rule: str = "gl"):
    """One case: ``(record, worst images)``; pyrender is the verdict's oracle, core a second opinion.

    ``images``: ``[(k, grey (H, W) uint8)]``; the style of their lines is read and their geometry
    measured (:mod:`oracles.line_style`), ``line_rule`` says whether aliased lines are held to GL's rule.
    """
    from wirecheck.core.pipeline import render_frame

    from .line_style import CaseStyle

    from .image_diagnose import diagnose_images, flipped_camera, oracle_segments

    per_frame, pr_scores, core_scores = [], [], []
    drawn_px = 0
    worst = None
    cand_imgs, segs, flipped = [], [], []
    camera = None
    style = CaseStyle(line_rule)
    for k, grey in images:
        p_model, edges, camera, m = frame_inputs(job_dir, job, scene, case, k)
        orac = oracles.get(camera.width, camera.height).render(p_model, edges, camera, model_matrix=m)[0]
        cand = style.frame(grey, orac, p_model, edges, camera, m)      # the pixels compared (>= 128)
        core = render_frame(p_model, edges, camera, m).image >= 128
        ps, cs = metrics.pixel_scores(cand, orac), metrics.pixel_scores(cand, core)
        pr_scores.append(ps)
        core_scores.append(cs)
        drawn_px += int((cand | orac).sum())
        per_frame.append({"frame": k, "f1_0px": ps["f1_0px"], "f1_1px": ps["f1_1px"],
                          "core_f1_0px": cs["f1_0px"], "core_f1_1px": cs["f1_1px"],
                          "candidate_pixels": ps["candidate_pixels"], "oracle_pixels": ps["oracle_pixels"]})
        key = (ps["f1_1px"], ps["f1_0px"])
        if worst is None or key < worst[0]:
            worst = (key, k, cand.copy(), orac.copy())
        if diagnose:
            p_world = p_model @ m[:3, :3].T + m[:3, 3]
            cand_imgs.append(cand)
            segs.append(oracle_segments(p_world, edges, camera))
            flipped.append(oracle_segments(p_world, edges, flipped_camera(camera)))
    s = _min_scores(pr_scores)
    rec = {"scene": scene, "camera": case, "camera_spec": camera.to_dict(), "frames": job["frames"],
           "frames_checked": len(images), "max_vertex_error_px": None,
           "pixel_f1_0px": s["f1_0px"], "pixel_f1_1px": s["f1_1px"],
           "pixel_f1_0px_mean": float(np.mean([x["f1_0px"] for x in pr_scores])),
           "pixel_f1_1px_mean": float(np.mean([x["f1_1px"] for x in pr_scores])),
           "pixel_precision_0px": s["precision_0px"], "pixel_recall_0px": s["recall_0px"],
           "pixel_precision_1px": s["precision_1px"], "pixel_recall_1px": s["recall_1px"],
           "core": _min_scores(core_scores), "worst_pixel_frame": worst[1]}
    rec["faults"] = diagnose_images(cand_imgs, segs, camera, flipped) if diagnose else []
    reasons = []
    if rec["pixel_f1_1px"] < tol.min_f1_1px:
        reasons.append(f"pixel F1@1px {rec['pixel_f1_1px']:.4f} < {tol.min_f1_1px} (frame {rec['worst_pixel_frame']})")
    if rec["pixel_f1_0px"] < tol.min_f1_0px:
        reasons.append(f"pixel F1@0px {rec['pixel_f1_0px']:.4f} < {tol.min_f1_0px}")
    reasons = style.judge(rec, reasons, tol)        # the line style's reading, its geometry and faults join
    if reasons and not rec["faults"]:
        # as the vertex diagnosis: a disagreement is never "no fault". Here no mirror, swap,
        # scale or offset explains the pixels: lines missing or extra, or another raster rule.
        rec["faults"] = [{"name": "unexplained"}]
    rec["compared"] = {"frames": len(images), "vertices": 0, "pixels": drawn_px}
    verdict = "fail" if reasons else "pass"
    if not reasons and drawn_px == 0:           # as oracles.gate: a case that compared nothing
        verdict = "vacuous"
        reasons = [f"vacuous: neither side drew a pixel in {len(images)} frames: nothing compared"]
    rec.update(verdict=verdict, reasons=reasons, per_frame=per_frame)
    return rec, {"frame": worst[1], "candidate": worst[2], "oracle": worst[3]}


def run_frames(job_dir, tol=None, diagnose: bool = True, name: str | None = None,
               allow_vacuous: bool = False, line_rule: str = "gl") -> tuple[dict, dict]:
    """Judge the job's frames: the report dict (as crosscheck's) and the worst-frame images.

    A case where neither side drew a pixel is ``"vacuous"`` and fails the run
    unless ``allow_vacuous`` (as :mod:`oracles.gate`); no vertex is compared here.
    ``line_rule``: ``"gl"`` holds aliased lines to GL's pixel rule, ``"geometry"``
    judges where the lines are only (:mod:`oracles.line_style`).

    FramesError (exit 2) when the job or its frames are incomplete, of the
    wrong size, unreadable, or not this job's.
    """
    from .pyrender_oracle import OracleCache
    from .tolerances import Tolerances

    tol = tol or Tolerances()
    t0 = time.perf_counter()
    job = load_job(job_dir)
    frames = load_frames(job_dir, job)
    oracles = OracleCache()
    records, images = [], {}
    try:
        for c in job["cases"]:
            rec, worst = judge_case(job_dir, job, c["scene"], c["case"], frames[(c["scene"], c["case"])],
                                    oracles, tol, diagnose=diagnose, line_rule=line_rule)
            records.append(rec)
            images[(c["scene"], c["case"])] = worst
        gl = oracles.gl_info()
    finally:
        oracles.close()
    failed = sum(r["verdict"] == "fail" for r in records)
    vacuous = sum(r["verdict"] == "vacuous" for r in records)
    compared = {"cases": sum(r["verdict"] != "vacuous" for r in records),
                "frames": sum(r["compared"]["frames"] for r in records), "vertices": 0,
                "pixels": sum(r["compared"]["pixels"] for r in records)}
    bad = failed or not compared["frames"] or (not allow_vacuous and (vacuous or not compared["pixels"]))
    report = {
        "tool": "wirecheck crosscheck", "verdict": "fail" if bad else "pass",
        "candidate": name or f"frames:{Path(job_dir).name}", "candidate_settings": None, "level": "frames",
        "style": "wireframe", "hidden_lines": False, "cull": "none", "oracles": ["pyrender", "core"],
        "oracle_gl": gl,
        "frames": job["frames"], "every": job["every"], "frames_checked": len(job["frame_numbers"]),
        "motion": job["motion"],
        "tolerances": {"vertex_error_px": tol.vertex_px, "min_pixel_f1_1px": tol.min_f1_1px,
                       "min_pixel_f1_0px": tol.min_f1_0px},
        "allow_vacuous": allow_vacuous, "line_rule": line_rule, "compared": compared,
        "summary": {"cases": len(records), "passed": len(records) - failed - vacuous, "failed": failed,
                    "vacuous": vacuous,
                    "max_vertex_error_px": None,
                    "min_pixel_f1_0px": min(r["pixel_f1_0px"] for r in records),
                    "min_pixel_f1_1px": min(r["pixel_f1_1px"] for r in records),
                    "min_core_f1_0px": min(r["core"]["f1_0px"] for r in records),
                    "min_core_f1_1px": min(r["core"]["f1_1px"] for r in records)},
        "cases": records,
        "timing": {"wall_s": time.perf_counter() - t0},
    }
    return report, images
