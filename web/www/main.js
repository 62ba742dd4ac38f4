// trisort's web player page: loads a baked file (?file=, default demo.baked, or a dropped
// one), plays it on the canvas with the wasm player (pkg/, made by web/build.sh), and shows
// play/pause, a scrub bar and the frame figures. ?backend=auto|webgpu|webgl2 and
// ?mode=blend|depth|saturate, ?shading=pbr|basic and ?tonemap=neutral|aces choose how. ?selfcheck=1 plays in depth mode and also draws the
// file's z-buffer twin on a hidden canvas: pixels where the two differ are holes on this
// browser (a triangle the frame leaves out is nearest there); the figures show their count.
// A file of several clips (camera paths) gets a clip choice: playback, the scrub bar and the
// arrow keys then stay within the clip's frames (frame numbers are the file's), at its rate.
// window.trisort exposes the player and the self-check to tests.
import init, { WebPlayer } from "./pkg/trisort_web.js";

const params = new URLSearchParams(location.search);
const backend = params.get("backend") || "auto";
const selfcheck = params.get("selfcheck") === "1";
const mode = selfcheck ? "depth" : params.get("mode") || "blend";
const shading = params.get("shading") || "pbr";
const tonemap = params.get("tonemap") || "neutral";
const $ = (id) => document.getElementById(id);
const canvas = $("canvas");

const state = { player: null, twin: null, frame: 0, playing: false, last: 0, ms: 0, checks: Promise.resolve() };
window.trisort = { state, ready: null, renderFrame, open, selfCheck, pixels, readFrame, compare, setClip, step };

// The RGBA pixels of a canvas or image (a canvas copied in the same task as its draw, while
// its drawing buffer holds the frame), and the 2D canvas holding the copy.
function pixels(source) {
  const ctx = new OffscreenCanvas(source.width, source.height).getContext("2d", { colorSpace: "srgb" });
  ctx.drawImage(source, 0, 0);
  return { data: ctx.getImageData(0, 0, source.width, source.height).data, canvas: ctx.canvas };
}

// Frame `frame` of `player` read back through a mapped buffer (WebPlayer.read_frame: the frame
// as the native player converts it; a WebGPU canvas cannot be read back in every browser), and
// a 2D canvas holding it.
async function readFrame(frame, player = state.player) {
  const [w, h] = [player.width(), player.height()];
  const data = await player.read_frame(frame);
  const image = new ImageData(new Uint8ClampedArray(data.buffer, data.byteOffset, data.length), w, h);
  const ctx = new OffscreenCanvas(w, h).getContext("2d", { colorSpace: "srgb" });
  ctx.putImageData(image, 0, 0);
  return { data: image.data, canvas: ctx.canvas };
}

// Two same-sized RGBA arrays compared on colour: pixels differing at all, pixels differing by
// more than 1/255, and the largest channel difference.
function compare(a, b) {
  let differing = 0, over1 = 0, max = 0;
  for (let i = 0; i < a.length; i += 4) {
    let d = 0;
    for (let c = 0; c < 3; c++) d = Math.max(d, Math.abs(a[i + c] - b[i + c]));
    if (d > 0) differing++;
    if (d > 1) over1++;
    max = Math.max(max, d);
  }
  return { differing, over1, max };
}

// Frame `frame` as played and as the z-buffer twin draws it: the holes (pixels that differ)
// and their largest channel difference. WebGL2 canvases are copied in the task that drew them;
// on WebGPU both frames are read back through mapped buffers.
// Checks run one after another (a WebGPU check waits for its reads).
function selfCheck(frame) {
  const run = state.checks.then(() => checkFrame(frame));
  state.checks = run.catch(() => {});
  return run;
}

async function checkFrame(frame) {
  if (!state.twin) throw new Error("open the page with ?selfcheck=1");
  // While checking, renderFrame does not start another check.
  state.checking = true;
  try {
    const mapped = state.player.backend() === "WebGPU";
    const ms = renderFrame(frame);
    const played = mapped ? (await readFrame(frame)).data : pixels($("canvas")).data;
    let twin;
    if (mapped) {
      twin = (await readFrame(frame, state.twin)).data;
    } else {
      state.twin.render(frame);
      twin = pixels($("twin")).data;
    }
    const { differing: holes, max } = compare(played, twin);
    $("figures").textContent = `${state.player.figures(frame, ms)} · ${holes} holes (self-check)`;
    return { frame, holes, max_channel_diff: max };
  } finally {
    state.checking = false;
  }
}

function showError(e) {
  $("error").textContent = String(e && e.message ? e.message : e);
  console.error(e);
}

// Draws `frame` and returns the milliseconds spent encoding and submitting it.
function renderFrame(frame) {
  const p = state.player;
  const t0 = performance.now();
  p.render(frame);
  state.ms = performance.now() - t0;
  state.frame = frame;
  $("scrub").value = String(frame);
  $("figures").textContent = p.figures(frame, state.ms);
  // With ?selfcheck=1 every frame shown is also checked (selfCheck writes the figures).
  if (state.twin && !state.checking) selfCheck(frame).catch(showError);
  return state.ms;
}

async function open(bytes, name) {
  $("error").textContent = "";
  if (state.player) {
    // A canvas keeps the context it was first given: a new file gets a fresh canvas.
    for (const [key, id] of [["player", "canvas"], ["twin", "twin"]]) {
      if (!state[key]) continue;
      state[key].free();
      state[key] = null;
      $(id).replaceWith($(id).cloneNode());
    }
  }
  const target = $("canvas");
  const p = await WebPlayer.open(target, bytes, name, backend, mode, false, shading, tonemap);
  if (selfcheck) {
    state.twin = await WebPlayer.open($("twin"), bytes, name, backend, mode, true, shading, tonemap);
  }
  state.player = p;
  state.frame = 0;
  const scrub = $("scrub");
  scrub.max = String(p.frame_count() - 1);
  scrub.disabled = false;
  $("play").disabled = false;
  $("device").textContent =
    `${name} · ${p.width()}×${p.height()} · ${p.backend()} on ${p.adapter()} · ` +
    `${p.bindings()} bindings, ${p.draw_path()} draws · ${mode} mode · ` +
    `baked for the ${p.raster_profile()} raster profile`;
  for (const w of p.warnings()) console.warn("trisort:", w);
  // The path's frame rate as baked, where the file says.
  if (p.fps()) $("fps").value = String(Math.round(p.fps()));
  const variants = p.variants();
  $("variant").replaceChildren(...["", ...variants].map((name) => {
    const o = document.createElement("option");
    o.value = name;
    o.textContent = name || "(default materials)";
    return o;
  }));
  $("variant-box").hidden = variants.length === 0;
  const clips = p.clips();
  $("clip").replaceChildren(...clips.map((name) => {
    const o = document.createElement("option");
    o.value = name;
    const [first, count] = p.clip_range(name);
    o.textContent = `${name} (frames ${first}–${first + count - 1})`;
    return o;
  }));
  $("clip-box").hidden = clips.length < 2;
  setClip(p.clip());
  return p;
}

// Selects clip `name` on the player (and the self-check's twin), restricts the scrub bar to
// its frames, takes its frame rate where the file has one, and shows its first frame.
function setClip(name) {
  const p = state.player;
  p.set_clip(name);
  if (state.twin) state.twin.set_clip(name);
  const first = p.clip_first();
  const scrub = $("scrub");
  scrub.min = String(first);
  scrub.max = String(first + p.clip_length() - 1);
  const fps = p.clip_fps(name) ?? p.fps();
  if (fps) $("fps").value = String(Math.round(fps));
  $("clip").value = name;
  renderFrame(first);
}

// Shows the frame after (+1) or before (-1) the one shown, looping within the clip.
function step(by) {
  return renderFrame(state.player.step_frame(state.frame, by));
}

async function fetchBaked(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status} ${r.statusText}`);
  return new Uint8Array(await r.arrayBuffer());
}

function tick(now) {
  if (!state.playing || !state.player) return;
  const fps = Math.max(1, Number($("fps").value) || 24);
  if (now - state.last >= 1000 / fps) {
    state.last = now;
    try { step(1); } catch (e) { state.playing = false; showError(e); }
  }
  requestAnimationFrame(tick);
}

function setPlaying(on) {
  state.playing = on && !!state.player;
  $("play").textContent = state.playing ? "Pause" : "Play";
  if (state.playing) requestAnimationFrame(tick);
}

$("play").addEventListener("click", () => setPlaying(!state.playing));
// A material variant: colours change, visibility does not (the player refuses variants that
// would change it, and the previous materials stay).
$("variant").addEventListener("change", (e) => {
  $("error").textContent = "";
  try {
    state.player.set_variant(e.target.value);
    if (state.twin) state.twin.set_variant(e.target.value);
    renderFrame(state.frame);
  } catch (err) { showError(err); }
});
$("clip").addEventListener("change", (e) => {
  $("error").textContent = "";
  try { setClip(e.target.value); } catch (err) { showError(err); }
});
$("scrub").addEventListener("input", (e) => {
  setPlaying(false);
  try { renderFrame(Number(e.target.value)); } catch (err) { showError(err); }
});
async function openFile(file) {
  setPlaying(false);
  try { await open(new Uint8Array(await file.arrayBuffer()), file.name); } catch (e) { showError(e); }
}
$("file").addEventListener("change", (e) => e.target.files[0] && openFile(e.target.files[0]));
const stage = $("stage");
stage.addEventListener("dragover", (e) => { e.preventDefault(); stage.classList.add("drop"); });
stage.addEventListener("dragleave", () => stage.classList.remove("drop"));
stage.addEventListener("drop", (e) => {
  e.preventDefault();
  stage.classList.remove("drop");
  if (e.dataTransfer.files[0]) openFile(e.dataTransfer.files[0]);
});
document.addEventListener("keydown", (e) => {
  if (!state.player || e.target.tagName === "INPUT") return;
  if (e.key === " ") { e.preventDefault(); setPlaying(!state.playing); }
  else if (e.key === "ArrowRight") { setPlaying(false); step(1); }
  else if (e.key === "ArrowLeft") { setPlaying(false); step(-1); }
});

window.trisort.ready = (async () => {
  await init();
  const file = params.get("file") || "demo.baked";
  await open(await fetchBaked(file), file);
  if (params.get("autoplay") !== "0" && !params.has("test")) setPlaying(true);
  return state.player;
})().catch((e) => { showError(e); throw e; });
