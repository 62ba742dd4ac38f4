// Reads a `trisort verify --report DIR` page back as Chromium sees it (tests/verify_report.rs):
//   node scripts/report-dom.mjs DIR/index.html [--chromium /usr/bin/chromium]
// Loads the file in Debian's headless Chromium through playwright-core (installed into
// web/test/node_modules by scripts/ensure-web.sh --browser-only), with every request other
// than the file itself and its data: URLs recorded (a self-contained report makes none), and
// prints JSON: the verdict banner, the clip rows and the frame rows in page order, each
// with its data-key cells and its images (decoded: naturalWidth > 0).
import { createRequire } from "node:module";
import { pathToFileURL } from "node:url";
import { resolve } from "node:path";

const require = createRequire(new URL("../web/test/package.json", import.meta.url));
const { chromium } = require("playwright-core");

const argv = process.argv.slice(2);
let file = null;
let executablePath = "/usr/bin/chromium";
for (let i = 0; i < argv.length; i++) {
  if (argv[i] === "--chromium") executablePath = argv[++i];
  else file = argv[i];
}
if (!file) {
  console.error("usage: node scripts/report-dom.mjs DIR/index.html [--chromium PATH]");
  process.exit(2);
}
const url = pathToFileURL(resolve(file)).href;
const browser = await chromium.launch({
  executablePath,
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run"],
});
try {
  const page = await browser.newPage();
  const requests = [];
  const consoleErrors = [];
  page.on("request", (r) => {
    const u = r.url();
    if (u !== url && !u.startsWith("data:")) requests.push(u);
  });
  page.on("console", (m) => { if (m.type() === "error") consoleErrors.push(m.text()); });
  page.on("pageerror", (e) => consoleErrors.push(String(e)));
  await page.goto(url, { waitUntil: "load", timeout: 30000 });
  const dom = await page.evaluate(async () => {
    // Every image decoded before it is measured.
    await Promise.all([...document.images].map((i) => i.decode().catch(() => {})));
    const cells = (tr) => Object.fromEntries(
      [...tr.querySelectorAll("td[data-key]")].map((td) => [td.dataset.key, td.textContent.trim()]));
    const banner = document.getElementById("verdict");
    return {
      title: document.title,
      scripts: document.scripts.length,
      verdict: { ok: banner?.dataset.ok, text: banner?.textContent.trim() },
      baked_hash: document.querySelector("#file-baked .hash")?.textContent.trim(),
      raster_profile: document.getElementById("raster-profile")?.textContent.trim(),
      tool_version: document.getElementById("tool-version")?.textContent.trim(),
      legend: document.getElementById("legend")?.textContent.replace(/\s+/g, " ").trim(),
      clips: [...document.querySelectorAll("#clips tr.clip")].map((tr) => ({
        clip: tr.dataset.clip,
        verdict: tr.querySelector(".verdict")?.textContent.trim(),
        ...cells(tr),
      })),
      frames: [...document.querySelectorAll("#frames tr.frame")].map((tr) => ({
        frame: Number(tr.dataset.frame),
        clip: tr.dataset.clip,
        verdict: tr.dataset.verdict,
        cells: cells(tr),
        images: [...tr.querySelectorAll("img")].map((img) => ({
          class: img.className,
          natural_width: img.naturalWidth,
          natural_height: img.naturalHeight,
          inline: img.getAttribute("src").startsWith("data:image/png;base64,"),
        })),
      })),
    };
  });
  console.log(JSON.stringify({ ...dom, requests, console_errors: consoleErrors }));
} finally {
  await browser.close();
}
