// Plays a baked file in Debian's headless Chromium (WebGL2 on SwiftShader, or WebGPU when
// asked and offered) through the web player page, reads chosen frames back from the canvas,
// and compares each with the native player's PNG of the same frame.
//
//   node web/test/browser.mjs --dist web/dist --native DIR --frames 0,12,24 --out DIR
//        [--backend webgl2] [--mode blend] [--shading pbr|basic] [--self-check no] [--file demo.baked] [--bad-file NAME]
//        [--variant-file NAME --variant VARIANT] [--clip-file NAME --clip CLIP]
//        [--chromium /usr/bin/chromium]
//
// Writes the browser's frames as DIR/frame-NNNNN.png (for `trisort verify --frames-dir`) and
// prints one JSON object: the device; per frame pixels differing from the native frame and
// the largest channel difference; and the page's self-check per frame (depth mode against the
// file's z-buffer twin, both drawn here: `holes`). Exit 0 when it ran; the caller gates.
import { createServer } from "node:http";
import { readFile, writeFile, mkdir } from "node:fs/promises";
import { extname, join, normalize } from "node:path";
import { chromium } from "playwright-core";

function args() {
  const a = { backend: "webgl2", mode: "blend", shading: "pbr", chromium: "/usr/bin/chromium", file: "demo.baked" };
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) a[argv[i].replace(/^--/, "")] = argv[i + 1];
  for (const k of ["dist", "native", "frames", "out"]) {
    if (!a[k]) throw new Error(`missing --${k}`);
  }
  a.frames = a.frames.split(",").map(Number);
  return a;
}

const TYPES = {
  ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm",
  ".png": "image/png", ".baked": "application/octet-stream",
};

// A static server: / is the page's folder, /native/ the native frames.
function serve(dist, native) {
  const server = createServer(async (req, res) => {
    const url = new URL(req.url, "http://x");
    let path = decodeURIComponent(url.pathname);
    const root = path.startsWith("/native/") ? native : dist;
    if (path.startsWith("/native/")) path = path.slice("/native".length);
    if (path === "/") path = "/index.html";
    const file = join(root, normalize(path).replace(/^(\.\.[/\\])+/, ""));
    try {
      const body = await readFile(file);
      res.writeHead(200, { "content-type": TYPES[extname(file)] || "application/octet-stream" });
      res.end(body);
    } catch {
      res.writeHead(404);
      res.end("not found");
    }
  });
  return new Promise((ok) => server.listen(0, "127.0.0.1", () => ok(server)));
}

const a = args();
const server = await serve(a.dist, a.native);
const port = server.address().port;
const browser = await chromium.launch({
  executablePath: a.chromium,
  headless: true,
  args: [
    "--no-sandbox", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", "--enable-unsafe-webgpu",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--no-first-run", "--disable-quic", "--force-color-profile=srgb",
    // WebGL2 on ANGLE over SwiftShader (`--use-angle=swiftshader`). WebGPU (Dawn on
    // SwiftShader's Vulkan) loses its device ("A valid external Instance reference no longer
    // exists") the first time a frame goes to its canvas unless the GPU process runs Vulkan
    // itself, without a Vulkan surface (tried on Chromium 156: the WebGL2 flags,
    // --disable-gpu-compositing, --in-process-gpu, Vulkan without the other two flags).
    ...(a.backend === "webgpu"
      ? ["--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=vulkan", "--disable-vulkan-surface"]
      : ["--use-angle=swiftshader"]),
  ],
});
let failed = null;
const logs = [];
// Opens the page with `query` and waits until it has opened its file. `guard(p)` races `p`
// against the page's first error: a panic in the wasm player leaves its promises unsettled.
async function openPlayer(query, label) {
  const page = await browser.newPage({ viewport: { width: 800, height: 800 }, deviceScaleFactor: 1 });
  // A hung page (a GPU process that never answers) fails the test instead of stalling CI.
  page.setDefaultTimeout(Number(a.timeout || 120) * 1000);
  page.on("console", (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on("pageerror", (e) => logs.push(`pageerror: ${e.message}`));
  const pageError = new Promise((_, reject) =>
    page.on("pageerror", (e) => reject(new Error(`${label}: page error: ${e.message}\n${logs.join("\n")}`))));
  pageError.catch(() => {});
  const guard = (p) => Promise.race([p, pageError]);
  await page.goto(`http://127.0.0.1:${port}/index.html?${query}&backend=${a.backend}&test=1`);
  try {
    await guard(page.waitForFunction(() => window.trisort && window.trisort.ready));
    await guard(page.evaluate(() => window.trisort.ready.then(() => true)));
  } catch (e) {
    throw new Error(`${label}: the page did not open the bake: ${e.message}\n${logs.join("\n")}`);
  }
  return { page, guard };
}
try {
  const { page, guard } = await openPlayer(`file=${a.file}&mode=${a.mode}&shading=${a.shading}`, "frames");
  const device = await page.evaluate(() => {
    const p = window.trisort.state.player;
    return {
      backend: p.backend(), adapter: p.adapter(), bindings: p.bindings(),
      draw_path: p.draw_path(), frames: p.frame_count(), width: p.width(), height: p.height(),
      raster_profile: p.raster_profile(), raster_depth_at: p.raster_depth_at(),
      user_agent: navigator.userAgent,
    };
  });
  await mkdir(a.out, { recursive: true });
  const frames = [];
  for (const frame of a.frames) {
    const r = await guard(page.evaluate(async (frame) => {
      const name = `frame-${String(frame).padStart(5, "0")}.png`;
      const t = window.trisort;
      const ms = t.renderFrame(frame);
      // WebGPU: read back through a mapped buffer (its canvas reads back blank here).
      const ours = t.state.player.backend() === "WebGPU"
        ? await t.readFrame(frame)
        : t.pixels(document.getElementById("canvas"));
      const resp = await fetch(`/native/${name}`);
      if (!resp.ok) throw new Error(`native frame ${name}: HTTP ${resp.status}`);
      const bmp = await createImageBitmap(await resp.blob(), {
        colorSpaceConversion: "none", premultiplyAlpha: "none",
      });
      if (bmp.width !== ours.canvas.width || bmp.height !== ours.canvas.height) {
        throw new Error(`native ${name} is ${bmp.width}x${bmp.height}, the canvas ${ours.canvas.width}x${ours.canvas.height}`);
      }
      const diff = t.compare(ours.data, t.pixels(bmp).data);
      const blob = await ours.canvas.convertToBlob({ type: "image/png" });
      const png = Array.from(new Uint8Array(await blob.arrayBuffer()));
      return {
        frame, ms, triangles: t.state.player.frame_triangles(frame),
        draws: t.state.player.frame_draws(frame), pixels: ours.data.length / 4,
        pixels_differing_native: diff.differing, pixels_over_1_native: diff.over1,
        max_channel_diff_native: diff.max, png, name,
      };
    }, frame));
    await writeFile(join(a.out, r.name), Buffer.from(r.png));
    delete r.png;
    delete r.name;
    frames.push(r);
    if (process.env.TRISORT_WEB_VERBOSE) console.error(`frame ${frame}: ${r.pixels_differing_native} px differ`);
  }
  // The on-device self-check: the same frames in depth mode against the file's z-buffer
  // twin, both drawn by this browser (holes on its rasterizer).
  // Skipped with `--self-check no` (a second run of the same file in another shading model:
  // depth mode does not shade).
  const selfCheck = [];
  if (a["self-check"] !== "no") {
    const { page: check, guard: guarded } = await openPlayer(`file=${a.file}&selfcheck=1`, "self-check");
    for (const frame of a.frames) {
      selfCheck.push(await guarded(check.evaluate((f) => window.trisort.selfCheck(f), frame)));
    }
  }
  const errors = logs.filter((l) => l.startsWith("error") || l.startsWith("pageerror"));
  // Bad input: a damaged file is refused on the page with a message naming it, no panic.
  let badFile = null;
  if (a["bad-file"]) {
    const bad = await browser.newPage();
    const badErrors = [];
    bad.on("pageerror", (e) => badErrors.push(e.message));
    await bad.goto(`http://127.0.0.1:${port}/index.html?file=${a["bad-file"]}&backend=${a.backend}&test=1`);
    await bad.waitForFunction(() => document.getElementById("error").textContent.length > 0);
    const message = await bad.evaluate(() => document.getElementById("error").textContent);
    const panicked = badErrors.some((m) => /unreachable|panicked/.test(m));
    badFile = { file: a["bad-file"], message, panicked };
  }
  // Material variants (KHR_materials_variants) chosen on the page: colours change.
  let variant = null;
  if (a["variant-file"]) {
    const { page: vp } = await openPlayer(`file=${a["variant-file"]}`, "variants");
    variant = await vp.evaluate((name) => {
      const t = window.trisort;
      const p = t.state.player;
      const canvas = document.getElementById("canvas");
      t.renderFrame(0);
      const before = t.pixels(canvas).data;
      const select = document.getElementById("variant");
      select.value = name;
      select.dispatchEvent(new Event("change"));
      const changed = t.compare(before, t.pixels(canvas).data).differing;
      let unknown = "";
      try { p.set_variant("no such variant"); } catch (e) { unknown = e.message; }
      return {
        name, variants: p.variants(), shown: !document.getElementById("variant-box").hidden,
        pixels_changed: changed, error: document.getElementById("error").textContent, unknown,
      };
    }, a.variant);
  }
  // Clips (the camera paths of a bundle) chosen on the page: the scrub bar, stepping and
  // playback stay within the chosen clip's frames, at its rate.
  let clip = null;
  if (a["clip-file"]) {
    const { page: cp } = await openPlayer(`file=${a["clip-file"]}`, "clips");
    clip = await cp.evaluate((name) => {
      const t = window.trisort;
      const p = t.state.player;
      const $ = (id) => document.getElementById(id);
      const clips = p.clips();
      const ranges = clips.map((c) => Array.from(p.clip_range(c)));
      const options = Array.from($("clip").options).map((o) => o.value);
      const shown = !$("clip-box").hidden;
      const initial = { clip: p.clip(), frame: t.state.frame, min: Number($("scrub").min), max: Number($("scrub").max) };
      $("clip").value = name;
      $("clip").dispatchEvent(new Event("change"));
      const first = p.clip_first(), length = p.clip_length(), last = first + length - 1;
      const selected = {
        clip: p.clip(), first, length, frame: t.state.frame,
        min: Number($("scrub").min), max: Number($("scrub").max), fps: Number($("fps").value),
        clip_fps: p.clip_fps(name) ?? null, figures: $("figures").textContent,
      };
      // Stepping and playback (which steps by one) loop within the clip.
      const visited = new Set();
      for (let k = 0; k < 2 * length; k++) { t.step(1); visited.add(t.state.frame); }
      t.renderFrame(last);
      t.step(1);
      const after_last = t.state.frame;
      t.step(-1);
      const before_first = t.state.frame;
      let unknown = "";
      try { p.set_clip("no-such-clip"); } catch (e) { unknown = e.message; }
      return {
        name, clips, ranges, options, shown, initial, selected, after_last, before_first,
        visited_min: Math.min(...visited), visited_max: Math.max(...visited), visited: visited.size,
        still: p.clip(), unknown, error: $("error").textContent,
      };
    }, a.clip);
  }
  console.log(JSON.stringify({ device, frames, self_check: selfCheck, bad_file: badFile, variant, clip, console_errors: errors }, null, 1));
} catch (e) {
  failed = e;
} finally {
  await browser.close();
  server.close();
}
if (failed) {
  console.error(`browser test: ${failed.message}`);
  process.exit(1);
}
