// trisort's web player page: loads a baked file (?file=, default demo.baked, or a dropped
// one), plays it on the canvas with the wasm player (pkg/, made by web/build.sh), and shows
// play/pause, a scrub bar and the frame figures. ?backend=auto|webgpu|webgl2 and
// ?mode=blend|depth|saturate choose how. window.trisort exposes the player to tests.
import init, { WebPlayer } from "./pkg/trisort_web.js";

const params = new URLSearchParams(location.search);
const backend = params.get("backend") || "auto";
const mode = params.get("mode") || "blend";
const $ = (id) => document.getElementById(id);
const canvas = $("canvas");

const state = { player: null, frame: 0, playing: false, last: 0, ms: 0 };
window.trisort = { state, ready: null, renderFrame, open };

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
  return state.ms;
}

async function open(bytes, name) {
  $("error").textContent = "";
  if (state.player) {
    // A canvas keeps the context it was first given: a new file gets a fresh canvas.
    const fresh = canvas.cloneNode();
    state.player.free();
    state.player = null;
    canvas.replaceWith(fresh);
  }
  const target = $("canvas");
  const p = await WebPlayer.open(target, bytes, name, backend, mode);
  state.player = p;
  state.frame = 0;
  const scrub = $("scrub");
  scrub.max = String(p.frame_count() - 1);
  scrub.disabled = false;
  $("play").disabled = false;
  $("device").textContent =
    `${name} · ${p.width()}×${p.height()} · ${p.backend()} on ${p.adapter()} · ` +
    `${p.bindings()} bindings, ${p.draw_path()} draws · ${mode} mode`;
  for (const w of p.warnings()) console.warn("trisort:", w);
  renderFrame(0);
  return p;
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
    const next = (state.frame + 1) % state.player.frame_count();
    try { renderFrame(next); } catch (e) { state.playing = false; showError(e); }
  }
  requestAnimationFrame(tick);
}

function setPlaying(on) {
  state.playing = on && !!state.player;
  $("play").textContent = state.playing ? "Pause" : "Play";
  if (state.playing) requestAnimationFrame(tick);
}

$("play").addEventListener("click", () => setPlaying(!state.playing));
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
  const n = state.player.frame_count();
  if (e.key === " ") { e.preventDefault(); setPlaying(!state.playing); }
  else if (e.key === "ArrowRight") { setPlaying(false); renderFrame((state.frame + 1) % n); }
  else if (e.key === "ArrowLeft") { setPlaying(false); renderFrame((state.frame + n - 1) % n); }
});

window.trisort.ready = (async () => {
  await init();
  const file = params.get("file") || "demo.baked";
  await open(await fetchBaked(file), file);
  if (params.get("autoplay") !== "0" && !params.has("test")) setPlaying(true);
  return state.player;
})().catch((e) => { showError(e); throw e; });
