#!/usr/bin/env bash
# Regenerates the README's pictures in reports/example/ from real runs.
#   bash reports/example/make.sh        (from the repo root, after bash .ci/setup.sh)
set -euo pipefail
cd "$(dirname "$0")/../.."
R=.venv/bin/renderer
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
$R --scene cube --frames 180 --camera-z 4.0 --fov 70 --out "$T/seed" >/dev/null     # the README's first example
CAM="--scene cube --frames 24 --camera-pos 2.5,2,3.5"
$R $CAM --out "$T/wf" >/dev/null
$R $CAM --cull backface --out "$T/cu" >/dev/null
$R $CAM --hidden-lines --out "$T/hl" >/dev/null
$R $CAM --style shaded --out "$T/sh" >/dev/null
$R $CAM --projection both --out "$T/both" >/dev/null
$R --scene orrery --frames 48 --camera-pos 2.6,3,5.2 --axes --hidden-lines --plots --format png,gif --out "$T/orr" >/dev/null
.venv/bin/python - "$T" <<'PY'
import sys
from pathlib import Path
from PIL import Image
t = Path(sys.argv[1]); out = Path("reports/example")
def frame(run, k, scene="cube"):
    return Image.open(t / run / f"{scene}-frames" / f"frame_{k:04d}.png").convert("RGB")
# four styles of the same frame, side by side, 1-px grey separators
tiles = [frame(r, 4) for r in ("wf", "cu", "hl", "sh")]
w, h = tiles[0].size
strip = Image.new("RGB", (4 * w + 3, h), (128, 128, 128))
for i, im in enumerate(tiles):
    strip.paste(im, (i * (w + 1), 0))
strip.save(out / "styles.png", optimize=True)
frame("both", 4).save(out / "perspective-orthographic.png", optimize=True)
frame("orr", 10, "orrery").save(out / "orrery-axes.png", optimize=True)
(out / "cube-frame_0020.png").write_bytes((t / "seed" / "cube-frames" / "frame_0020.png").read_bytes())
(out / "orrery.gif").write_bytes((t / "orr" / "orrery.gif").read_bytes())
(out / "orrery-plots.png").write_bytes((t / "orr" / "orrery-plots.png").read_bytes())
PY
echo "wrote reports/example/{cube-frame_0020,styles,perspective-orthographic,orrery-axes,orrery-plots}.png, orrery.gif"

# renderer --compare (docs/interactive.md): the 2x2 picture of camera z 3/6 and FOV 60/90
$R --compare --out "$T/cmp" > "$T/cmp.txt"
cp "$T/cmp/cube-compare.png" reports/example/cube-compare.png
# the viewer page after the browser test's drag, wheel, shift-drag and overlay (needs tests/browser/setup.sh)
if [ -d tests/browser/node_modules/playwright-core ] && [ -x /usr/bin/chromium ]; then
    .venv/bin/python - "$T" <<'PY'
import subprocess, sys
from wirecheck.core.app.cli import build_parser, settings_from_args
from wirecheck.core.app.viewer import Server, Viewer
from wirecheck.oracles.live import LiveOverlay
s = settings_from_args(build_parser().parse_args(["--out", sys.argv[1] + "/viewer"]))
server = Server(Viewer(s, overlay=LiveOverlay())).start()
try:
    subprocess.run(["node", "tests/browser/viewer_session.mjs", server.url, sys.argv[1] + "/session.json",
                    "reports/example/viewer.png"], check=True)
finally:
    server.stop()
PY
    echo "wrote reports/example/cube-compare.png, viewer.png"
fi
