// The npm package as an app installs it: serves web/test/pkg-consumer (with the tarball
// installed in its node_modules by web/test/run.sh) in Debian's headless Chromium, runs its
// page (app.mjs: the package imported by name through an import map, the demo bake opened with
// the options object, one frame drawn and compared with the native player's, the typed errors
// provoked) and prints what it found as JSON. The caller gates.
//
// With --webgpu, a second Chromium with WebGPU kept (browser.mjs's flags) opens the page again
// and plays frame 0 through `backend: "webgpu"`, read back with readFrame ("webgpu_run").
//
// With --three, the same browser then opens three.html (three-app.mjs: `TrisortMesh` from
// @trisort/player/three in three.js scenes, every frame of the file in the id-colour mode
// checked against the z-buffer and against plain WebGL2) and adds what it found as "three":
// --three-file (default --file) at --three-samples (default 0: one sample at the pixel centre).
//
//   node web/test/pkg.mjs --consumer web/test/pkg-consumer --dist web/dist --native DIR
//        [--file demo.baked] [--bad-file truncated.baked] [--frame 0] [--backend webgl2]
//        [--webgpu yes] [--three yes [--three-file demo-1x.baked] [--three-samples 0]]
import { createServer } from "node:http";
import { readFile } from "node:fs/promises";
import { extname, join, normalize } from "node:path";
import { chromium } from "playwright-core";

const a = { file: "demo.baked", "bad-file": "truncated.baked", frame: "0", backend: "webgl2", chromium: "/usr/bin/chromium" };
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i += 2) a[argv[i].replace(/^--/, "")] = argv[i + 1];
for (const k of ["consumer", "dist", "native"]) if (!a[k]) throw new Error(`missing --${k}`);

const TYPES = {
  ".html": "text/html", ".js": "text/javascript", ".mjs": "text/javascript",
  ".wasm": "application/wasm", ".png": "image/png", ".json": "application/json",
};
// / is the consumer project, /dist/ the built page's folder (the bakes), /native/ the frames.
const server = createServer(async (req, res) => {
  let path = decodeURIComponent(new URL(req.url, "http://x").pathname);
  let root = a.consumer;
  for (const [prefix, dir] of [["/dist/", a.dist], ["/native/", a.native]]) {
    if (path.startsWith(prefix)) { root = dir; path = path.slice(prefix.length - 1); }
  }
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
await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
const browser = await chromium.launch({
  executablePath: a.chromium,
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist", "--disable-background-networking", "--disable-component-update",
    "--disable-sync", "--no-first-run", "--force-color-profile=srgb"],
});
const logs = [];
let code = 0;
try {
  const page = await browser.newPage({ viewport: { width: 600, height: 600 }, deviceScaleFactor: 1 });
  page.setDefaultTimeout(120_000);
  page.on("console", (m) => logs.push(`${m.type()}: ${m.text()}`));
  page.on("pageerror", (e) => logs.push(`pageerror: ${e.message}`));
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await page.waitForFunction(() => window.packageLoaded || null).catch((e) => {
    throw new Error(`the page did not load the package: ${e.message}\n${logs.join("\n")}`);
  });
  const frame = Number(a.frame);
  const result = await page.evaluate((o) => window.runPackageTest(o), {
    file: `/dist/${a.file}`, badFile: `/dist/${a["bad-file"]}`, backend: a.backend, frame,
    native: `/native/frame-${String(frame).padStart(5, "0")}.png`,
  });
  // The package on WebGPU: Chromium again, with the flags that keep a WebGPU device in this
  // headless browser (web/test/browser.mjs says why), the page opened afresh.
  if (a.webgpu) {
    const gpuBrowser = await chromium.launch({
      executablePath: a.chromium, headless: true,
      args: ["--no-sandbox", "--enable-unsafe-swiftshader", "--enable-unsafe-webgpu",
        "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=vulkan",
        "--disable-vulkan-surface", "--disable-background-networking", "--disable-component-update",
        "--disable-sync", "--no-first-run", "--force-color-profile=srgb"],
    });
    try {
      const gpuPage = await gpuBrowser.newPage({ viewport: { width: 600, height: 600 }, deviceScaleFactor: 1 });
      gpuPage.setDefaultTimeout(120_000);
      gpuPage.on("console", (m) => logs.push(`${m.type()}: ${m.text()}`));
      gpuPage.on("pageerror", (e) => logs.push(`pageerror: ${e.message}`));
      await gpuPage.goto(`http://127.0.0.1:${server.address().port}/`);
      await gpuPage.waitForFunction(() => window.packageLoaded || null);
      result.webgpu_run = await gpuPage.evaluate((o) => window.runWebGpuTest(o), {
        file: `/dist/${a.file}`, frame, native: `/native/frame-${String(frame).padStart(5, "0")}.png`,
      });
    } finally {
      await gpuBrowser.close();
    }
  }
  if (a.three) {
    const t0 = Date.now();
    await page.goto(`http://127.0.0.1:${server.address().port}/three.html?samples=${a["three-samples"] ?? 0}`);
    await page.waitForFunction(() => window.threeLoaded || null).catch((e) => {
      throw new Error(`the page did not load three.js and @trisort/player/three: ${e.message}\n${logs.join("\n")}`);
    });
    result.three = await page.evaluate((o) => window.runThreeTest(o), { file: `/dist/${a["three-file"] ?? a.file}` });
    result.three.seconds = (Date.now() - t0) / 1000;
  }
  result.console_errors = logs.filter((l) => l.startsWith("error") || l.startsWith("pageerror"));
  console.log(JSON.stringify(result, null, 1));
} catch (e) {
  console.error(`package test: ${e.message}\n${logs.join("\n")}`);
  code = 1;
} finally {
  await browser.close();
  server.close();
}
process.exit(code);
