// Draws a wirecheck frames job (crosscheck export DIR) with three.js's
// WebGLRenderer in headless Chromium (Debian's, via playwright-core), as a
// three.js user would: PerspectiveCamera / OrthographicCamera from the job's
// camera fields and lookAt, the scene's OBJ edges as LineSegments with a white
// LineBasicMaterial on black, the frame's model matrix on the object,
// antialias off. Each frame is read back with canvas.toDataURL and written to
// DIR/frames/<scene>/<case>/frame_NNNN.png. tests/test_frames_three.py judges
// them with crosscheck --candidate-frames.
//
//   node frames_three.mjs JOB_DIR THREE_MODULE_JS [--antialias]
import { chromium } from "playwright-core";
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";

const [jobDir, threePath, ...flags] = process.argv.slice(2);
const antialias = flags.includes("--antialias");
const job = JSON.parse(readFileSync(join(jobDir, "job.json"), "utf8"));

function readObj(path) {
  const v = [], l = [];
  for (const line of readFileSync(path, "utf8").split("\n")) {
    const p = line.trim().split(/\s+/);
    if (p[0] === "v") v.push(p.slice(1, 4).map(Number));
    else if (p[0] === "l") l.push([Number(p[1]) - 1, Number(p[2]) - 1]);
  }
  return { v, l };
}

const page_html = `<!doctype html><html><body style="margin:0;background:#000">
<script type="module">
import * as THREE from "/three.module.js";
window.drawFrame = ({ width, height, camera, model, positions, antialias }) => {
  const canvas = document.createElement("canvas");
  const renderer = new THREE.WebGLRenderer({ canvas, antialias, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(width, height, false);
  renderer.setClearColor(0x000000, 1);
  const aspect = width / height;
  let cam;
  if (camera.projection === "perspective") {
    cam = new THREE.PerspectiveCamera(camera.fov_y_deg, aspect, camera.near, camera.far);
  } else {
    const h = camera.ortho_height / 2;
    cam = new THREE.OrthographicCamera(-aspect * h, aspect * h, h, -h, camera.near, camera.far);
  }
  const [px, py, pz] = camera.position, [fx, fy, fz] = camera.forward;
  cam.position.set(px, py, pz);
  cam.up.set(...camera.up);
  cam.lookAt(px + fx, py + fy, pz + fz);
  cam.updateMatrixWorld(true);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions, 3));
  const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0xffffff }));
  lines.matrixAutoUpdate = false;
  lines.matrix.set(...model.flat());
  const scene = new THREE.Scene();
  scene.add(lines);
  renderer.render(scene, cam);
  const url = canvas.toDataURL("image/png");
  geometry.dispose();
  renderer.dispose();
  return url;
};
window.ready = true;
</script></body></html>`;

// Chromium's profile (2-3 MB): in WIRECHECK_PROFILE_PARENT when the test gives one (its own temporary
// folder, so even a killed run leaves nothing in the system's), removed whenever node exits.
const userDataDir = mkdtempSync(join(process.env.WIRECHECK_PROFILE_PARENT || tmpdir(), "wirecheck-chromium-"));
process.on("exit", () => rmSync(userDataDir, { recursive: true, force: true, maxRetries: 3 }));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath: process.env.WIRECHECK_CHROMIUM || "/usr/bin/chromium",
  headless: true,
  args: ["--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"],
});
const page = context.pages()[0] || await context.newPage();
const errors = [];
page.on("pageerror", (e) => errors.push(String(e)));
page.on("console", (m) => {   // the favicon request is not routed: not an error of the drawing
  if (m.type() === "error" && !m.text().startsWith("Failed to load resource")) errors.push(m.text());
});
await page.route("http://wirecheck.invalid/**", (route) => {
  const name = new URL(route.request().url()).pathname.slice(1);
  if (/^[a-z.]+\.js$/.test(name)) {      // three.module.js and the modules it imports (three.core.js)
    return route.fulfill({ contentType: "text/javascript", body: readFileSync(join(dirname(threePath), name), "utf8") });
  }
  return route.fulfill({ contentType: "text/html", body: page_html });
});
await page.goto("http://wirecheck.invalid/");
await page.waitForFunction(() => window.ready === true, null, { timeout: 60000 }).catch((e) => {
  throw new Error(`the page did not load three.js: ${errors.join("; ") || e.message}`);
});

let drawn = 0;
for (const c of job.cases) {
  const sceneRow = job.scenes.find((s) => s.name === c.scene);
  for (const rel of c.frames) {
    const k = rel.match(/frame_(\d+)\.png$/)[1];
    const cam = JSON.parse(readFileSync(join(jobDir, "cameras", c.scene, c.case, `frame_${k}.json`), "utf8"));
    const obj = readObj(join(jobDir, sceneRow.space === "model" ? sceneRow.obj : `scenes/${c.scene}/frame_${k}.obj`));
    const positions = obj.l.flatMap(([a, b]) => [...obj.v[a], ...obj.v[b]]);
    const url = await page.evaluate((d) => window.drawFrame(d),
      { width: c.width, height: c.height, camera: cam.camera, model: cam.model_matrix, positions, antialias });
    if (errors.length) throw new Error(errors.join("\n"));
    mkdirSync(dirname(join(jobDir, rel)), { recursive: true });
    writeFileSync(join(jobDir, rel), Buffer.from(url.split(",")[1], "base64"));
    drawn += 1;
  }
}
await context.close();
console.log(`three.js ${antialias ? "(antialias on)" : "(antialias off)"}: ${drawn} frames drawn`);
