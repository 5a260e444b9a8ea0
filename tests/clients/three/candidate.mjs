// A wirecheck candidate on three.js: the candidate protocol, version 1 (docs/protocol.md).
//
// Each request's camera becomes a three.js PerspectiveCamera or
// OrthographicCamera (position, up, lookAt(position + forward)); points are
// projected with Vector3.project (three.js's own view and projection
// matrices). Only the viewport is converted here, from normalised device
// coordinates (x right, y up, [-1, 1]) to pixels:
//
//   --pixels wirecheck (default)  wirecheck's pixels: integer coordinates at pixel
//                                 centres, y down (core/conventions.py):
//                                 x = (ndc.x + 1) W/2 - 0.5,  y = (1 - ndc.y) H/2 - 0.5
//   --pixels docs                 the screen-position idiom of three.js examples:
//                                 x = (ndc.x + 1) W/2,  y = (1 - ndc.y) H/2  (corner origin)
//   --pixels webgl                WebGL window coordinates (gl_FragCoord):
//                                 x = (ndc.x + 1) W/2,  y = (ndc.y + 1) H/2  (corner origin, y up)
//
// A point whose view depth (-z in three.js's camera space) is outside
// [near, far] is clipped: NaN, NaN.
//
// Run: (cd tests/clients/three && npm ci) then
//      crosscheck --candidate-cmd 'node tests/clients/three/candidate.mjs'
import * as THREE from 'three';

const HEADER = 'wirecheck-candidate 1\n';
const args = process.argv.slice(2);
const pixels = args[0] === '--pixels' ? args[1] : 'wirecheck';
if (!['wirecheck', 'docs', 'webgl'].includes(pixels)) {
  process.stderr.write(`candidate.mjs: --pixels ${pixels}: expected wirecheck, docs or webgl\n`);
  process.exit(2);
}

function threeCamera(c) {
  const aspect = c.width / c.height;
  let camera;
  if (c.projection === 'perspective') {
    camera = new THREE.PerspectiveCamera(c.fov_y_deg, aspect, c.near, c.far);
  } else {
    const top = c.ortho_height / 2;
    camera = new THREE.OrthographicCamera(-top * aspect, top * aspect, top, -top, c.near, c.far);
  }
  camera.position.fromArray(c.position);
  camera.up.fromArray(c.up);
  camera.lookAt(new THREE.Vector3().fromArray(c.position).add(new THREE.Vector3().fromArray(c.forward)));
  camera.updateMatrixWorld(true);
  return camera;
}

function project(c, points, n) {
  const camera = threeCamera(c);
  const W = c.width, H = c.height;
  const out = new Float64Array(2 * n);
  const p = new THREE.Vector3(), view = new THREE.Vector3();
  for (let i = 0; i < n; i++) {
    p.set(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    const depth = -view.copy(p).applyMatrix4(camera.matrixWorldInverse).z;
    if (!(depth >= c.near && depth <= c.far)) {
      out[2 * i] = out[2 * i + 1] = NaN;
      continue;
    }
    p.project(camera);                      // normalised device coordinates
    if (pixels === 'wirecheck') {
      out[2 * i] = (p.x + 1) * W / 2 - 0.5;
      out[2 * i + 1] = (1 - p.y) * H / 2 - 0.5;
    } else if (pixels === 'docs') {
      out[2 * i] = (p.x + 1) * W / 2;
      out[2 * i + 1] = (1 - p.y) * H / 2;
    } else {
      out[2 * i] = (p.x + 1) * W / 2;
      out[2 * i + 1] = (p.y + 1) * H / 2;
    }
  }
  return out;
}

// ---- the protocol: a byte queue read as lines and fixed-size payloads
let queue = Buffer.alloc(0);
let state = 'header';         // header -> request line -> points -> request line ...
let request = null;

function send(buf) { process.stdout.write(buf); }

function step() {
  for (;;) {
    if (state === 'points') {
      const bytes = request.n * 24;
      if (queue.length < bytes) return;
      const copy = new Uint8Array(queue.subarray(0, bytes));   // aligned for Float64Array
      queue = queue.subarray(bytes);
      const px = project(request.camera, new Float64Array(copy.buffer), request.n);
      send(Buffer.concat([Buffer.from(JSON.stringify({ n: request.n }) + '\n'),
                          Buffer.from(px.buffer, px.byteOffset, px.byteLength)]));
      state = 'request';
      continue;
    }
    const nl = queue.indexOf(10);
    if (nl < 0) return;
    const line = queue.subarray(0, nl + 1).toString('utf8');
    queue = queue.subarray(nl + 1);
    if (state === 'header') {
      if (line !== HEADER) {
        send(JSON.stringify({ error: `expected the header ${JSON.stringify(HEADER)}` }) + '\n');
        process.exit(2);
      }
      send(HEADER);
      state = 'request';
    } else {
      request = JSON.parse(line);
      state = 'points';
    }
  }
}

// chunks are gathered and joined only when a whole request is there (no quadratic copying)
let pending = [], pendingBytes = 0;
process.stdin.on('data', (chunk) => {
  pending.push(chunk);
  pendingBytes += chunk.length;
  const need = state === 'points' ? request.n * 24 : 1;
  if (state === 'points' ? queue.length + pendingBytes < need : chunk.indexOf(10) < 0) return;
  queue = Buffer.concat([queue, ...pending]);
  pending = [];
  pendingBytes = 0;
  step();
});
process.stdin.on('end', () => process.exit(0));
