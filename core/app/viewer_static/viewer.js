// The viewer page: sends input to the server and shows what comes back.
// Every frame is drawn by core on the server (core/app/viewer.py); nothing here
// projects a point. At most one request is in flight: input arriving meanwhile
// is merged into the next request, so a slow frame never builds a backlog.
"use strict";

// server stages (core.app.profile), the overlay's crosscheck, then what the server did not see
const STAGES = ["transform", "faces", "shading", "clip", "raster", "compose", "encode", "oracle", "transfer"];
const COLOURS = {transform: "#1f77b4", faces: "#ff7f0e", shading: "#2ca02c", clip: "#d62728",
                 raster: "#9467bd", compose: "#8c564b", encode: "#e377c2", oracle: "#bcbd22",
                 transfer: "#7f7f7f"};
const WINDOW = 120;          // frames in the chart and the p50/p95
const history = [];          // per frame: {stage: ms, roundtrip: ms, server: ms}
let pending = [];            // ops not yet sent
let inflight = false;
let forceNext = false;
let overlayOn = false;
let playTimer = null;

const $ = (id) => document.getElementById(id);

function addOp(op) {
  const tail = pending[pending.length - 1];
  if (tail && tail.op === op.op && (op.op === "orbit" || op.op === "pan")) { tail.dx += op.dx; tail.dy += op.dy; }
  else if (tail && tail.op === op.op && op.op === "dolly") { tail.delta += op.delta; }
  else if (tail && tail.op === op.op && op.op === "step") { tail.n += op.n; }
  else if (tail && tail.op === op.op && op.op === "set" && tail.field === op.field) { tail.value = op.value; }
  else { pending.push(op); }
  pump();
}

function pump() {
  if (inflight || (pending.length === 0 && !forceNext)) return;
  inflight = true;
  forceNext = false;
  const ops = pending;
  pending = [];
  // the server's reset keeps the frame; the page's reset (and a fresh page) goes back to frame 1 too
  const resets = ops.some((o) => o.op === "reset");
  const t0 = performance.now();
  // a frame takes milliseconds; the overlay's first frame seconds (pyrender starts): say so
  const busy = setTimeout(() => {
    $("busy").textContent = overlayOn ? "drawing the oracle overlay (pyrender; the first takes a few seconds)\u2026"
                                      : "drawing\u2026";
    $("busy").hidden = false;
  }, 300);
  fetch("/api/frame", {method: "POST", headers: {"Content-Type": "application/json"},
                       body: JSON.stringify({ops: ops, overlay: overlayOn})})
    .then((r) => r.json())
    .then((resp) => {
      show(resp, performance.now() - t0);
      if (resets && resp.view && resp.view.frame !== 1) addOp({op: "step", n: 1 - resp.view.frame});
    })
    .catch((err) => showMessage("request failed: " + err))
    .finally(() => { clearTimeout(busy); $("busy").hidden = true; inflight = false; pump(); });
}

function refresh() { forceNext = true; pump(); }

// true when nothing is in flight or waiting (the browser test waits on it)
window.viewerIdle = () => !inflight && pending.length === 0 && !forceNext;

function showMessage(text) {
  const box = $("message");
  box.textContent = text || "";
  box.hidden = !text;
}

function fmt(v) { return v.map((x) => x.toFixed(4)).join(", "); }

function show(resp, roundtrip) {
  showMessage(resp.error);
  if (!resp.image) return;
  $("frame").src = "data:image/png;base64," + resp.image;
  const v = resp.view, c = resp.camera;
  for (const el of document.querySelectorAll(".field")) {
    if (document.activeElement !== el || resp.error) el.value = String(v[el.dataset.field]);
  }
  $("fov-range").value = String(v.fov);
  for (const el of document.querySelectorAll(".choice")) el.value = v[el.dataset.field];
  for (const el of document.querySelectorAll(".flag")) el.checked = v[el.dataset.field];
  $("frame-no").textContent = `frame ${v.frame} of ${resp.frames}`;
  $("camera-text").textContent =
    `position (${fmt(c.position)})\nforward  (${fmt(c.forward)})\nup       (${fmt(c.up)})\n` +
    `look-at  (${fmt(v.target)})`;
  $("command").value = resp.command;
  $("view-json").textContent = JSON.stringify({frame: v.frame, frames: resp.frames, camera: c, view: v,
                                               vertices_px: resp.vertices_px}, null, 1);
  const rec = {};
  for (const s of STAGES) rec[s] = resp.timing_ms[s] || 0;
  rec.oracle = resp.overlay_ms || 0;
  rec.transfer = Math.max(0, roundtrip - resp.timing_ms.total - rec.oracle);
  rec.roundtrip = roundtrip;
  rec.server = resp.timing_ms.total;
  history.push(rec);
  if (history.length > WINDOW) history.shift();
  drawProfile();
  showOverlay(resp.overlay);
}

function showOverlay(ov) {
  const on = overlayOn && ov;
  for (const el of document.querySelectorAll(".overlay")) el.hidden = !on;
  $("overlay-box").hidden = !on;
  if (!on) return;
  if (ov.oracle_image) $("oracle").src = "data:image/png;base64," + ov.oracle_image;
  if (ov.diff_image) $("diff").src = "data:image/png;base64," + ov.diff_image;
  const shown = {};
  for (const k of Object.keys(ov)) if (!k.endsWith("_image")) shown[k] = ov[k];
  $("overlay-json").textContent = JSON.stringify(shown, null, 1);
}

function percentile(values, p) {
  const s = values.slice().sort((a, b) => a - b);
  const x = (s.length - 1) * p, i = Math.floor(x), j = Math.min(i + 1, s.length - 1);
  return s[i] + (s[j] - s[i]) * (x - i);
}

function drawProfile() {
  const canvas = $("chart"), ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const top = Math.max(...history.map((r) => r.roundtrip), 1);
  const w = canvas.width / WINDOW;
  history.forEach((r, i) => {
    let y = canvas.height;
    for (const s of STAGES) {
      const h = (r[s] / top) * (canvas.height - 12);
      ctx.fillStyle = COLOURS[s];
      ctx.fillRect(i * w, y - h, Math.max(w - 1, 1), h);
      y -= h;
    }
  });
  ctx.fillStyle = "#000";
  ctx.fillText(`${top.toFixed(1)} ms`, 2, 10);
  const rows = STAGES.concat(["server", "roundtrip"]).map((s) => {
    const vals = history.map((r) => r[s]);
    const sw = COLOURS[s] ? `<span class="swatch" style="background:${COLOURS[s]}"></span>` : "";
    return `<tr data-stage="${s}"><td>${sw}${s}</td><td>${vals[vals.length - 1].toFixed(3)}</td>` +
           `<td>${percentile(vals, 0.5).toFixed(3)}</td><td>${percentile(vals, 0.95).toFixed(3)}</td></tr>`;
  });
  $("profile-table").tBodies[0].innerHTML = rows.join("");
  const mean = history.reduce((a, r) => a + r.roundtrip, 0) / history.length;
  $("fps").textContent = `${(1000 / mean).toFixed(1)} frames/s over the last ${history.length} frames`;
}

// ---- input
let drag = null;
const img = $("frame");
img.addEventListener("mousedown", (e) => { drag = {x: e.clientX, y: e.clientY}; e.preventDefault(); });
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag = {x: e.clientX, y: e.clientY};
  if (dx || dy) addOp({op: e.shiftKey ? "pan" : "orbit", dx: dx, dy: dy});
});
window.addEventListener("mouseup", () => { drag = null; });
img.addEventListener("wheel", (e) => {
  e.preventDefault();
  addOp({op: "dolly", delta: e.deltaMode === 1 ? 16 * e.deltaY : e.deltaY});
}, {passive: false});

for (const el of document.querySelectorAll(".field")) {
  el.addEventListener("change", () => addOp({op: "set", field: el.dataset.field, value: el.value}));
}
$("fov-range").addEventListener("input", (e) => addOp({op: "set", field: "fov", value: e.target.value}));
for (const el of document.querySelectorAll(".choice")) {
  el.addEventListener("change", () => addOp({op: "set", field: el.dataset.field, value: el.value}));
}
for (const el of document.querySelectorAll(".flag")) {
  el.addEventListener("change", () => addOp({op: "set", field: el.dataset.field, value: el.checked}));
}
$("overlay").addEventListener("change", (e) => { overlayOn = e.target.checked; refresh(); });
$("reset").addEventListener("click", () => addOp({op: "reset"}));
$("step").addEventListener("click", () => addOp({op: "step", n: 1}));
$("step-back").addEventListener("click", () => addOp({op: "step", n: -1}));
$("play").addEventListener("click", () => {
  if (playTimer) { clearInterval(playTimer); playTimer = null; $("play").textContent = "play"; return; }
  playTimer = setInterval(() => addOp({op: "step", n: 1}), 1000 / 30);
  $("play").textContent = "pause";
});
$("copy").addEventListener("click", () => {
  const text = $("command").value;
  const fallback = () => { $("command").select(); document.execCommand("copy"); };
  if (navigator.clipboard) navigator.clipboard.writeText(text).catch(fallback); else fallback();
});

// a reload starts fresh: the server's view goes back to the start, and the browser's remembered
// form state (the overlay box) is cleared
$("overlay").checked = false;
addOp({op: "reset"});
