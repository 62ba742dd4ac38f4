// A page that uses the npm package as an app would (web/test/pkg.mjs drives it): imports it by
// its name, opens the demo bake with the options object, draws a frame, and checks the typed
// errors. window.runPackageTest(options) returns what the test gates.
import {
  TrisortPlayer, TrisortError, TrisortFormatError, TrisortOptionError,
} from "@trisort/player";

async function fetchBytes(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return new Uint8Array(await r.arrayBuffer());
}

// The RGBA pixels of a canvas or image.
function pixels(source) {
  const ctx = new OffscreenCanvas(source.width, source.height).getContext("2d", { colorSpace: "srgb" });
  ctx.drawImage(source, 0, 0);
  return ctx.getImageData(0, 0, source.width, source.height).data;
}

// Two same-sized RGBA arrays: pixels differing at all, by more than 1/255, and lit in `a`.
function compare(a, b) {
  let differing = 0, over1 = 0, lit = 0;
  for (let i = 0; i < a.length; i += 4) {
    let d = 0;
    for (let c = 0; c < 3; c++) d = Math.max(d, Math.abs(a[i + c] - b[i + c]));
    if (d > 0) differing++;
    if (d > 1) over1++;
    if (a[i] + a[i + 1] + a[i + 2] > 0) lit++;
  }
  return { differing, over1, lit };
}

// How `promise` (or function) fails: its class, code and message; null when it does not.
async function failure(f) {
  try {
    await f();
    return null;
  } catch (e) {
    return {
      class: e.constructor.name, code: e.code, message: e.message,
      is_trisort: e instanceof TrisortError, is_error: e instanceof Error,
    };
  }
}

window.runPackageTest = async ({ file, badFile, backend, native, frame }) => {
  const canvas = document.getElementById("canvas");
  const data = await fetchBytes(file);
  const player = await TrisortPlayer.open({
    canvas, data, name: file, backend, mode: "blend", shading: "pbr", tonemap: "neutral",
  });
  const ms = player.render(frame);
  const ours = pixels(canvas);
  const bmp = await createImageBitmap(await (await fetch(native)).blob(), {
    colorSpaceConversion: "none", premultiplyAlpha: "none",
  });
  const theirs = pixels(bmp);
  const { over1, lit } = compare(ours, theirs);
  // The same frame read back through a mapped buffer (readFrame): the native player's
  // conversion of the off-screen frame, here compared with the canvas; a second read before the
  // first settles is refused.
  const reading = player.readFrame(frame);
  const busy = await failure(() => player.readFrame(frame));
  const read = await reading;
  const readDiffers = compare(read, ours).differing;
  const readOver1Native = compare(read, theirs).over1;
  const bad = await fetchBytes(badFile);
  const result = {
    backend: player.backend, frames: player.frameCount, width: player.width, height: player.height,
    clips: player.clips(), stats: player.frameStats(frame), ms, pixels: ours.length / 4,
    lit, over1_native: over1,
    read_frame: { bytes: read.length, is_uint8array: read instanceof Uint8Array, differs_from_canvas: readDiffers,
      over1_native: readOver1Native, busy },
    truncated: await failure(() => TrisortPlayer.open({ canvas: document.createElement("canvas"), data: bad, name: badFile, backend })),
    bad_option: await failure(() => TrisortPlayer.open({ canvas, data, backend: "vulkan" })),
    no_canvas: await failure(() => TrisortPlayer.open({ data })),
    unknown_clip: await failure(() => player.setClip("no-such-clip")),
    // Where this browser has no WebGPU adapter (pkg.mjs does not enable it): TrisortDeviceError.
    webgpu: await failure(async () => {
      (await TrisortPlayer.open({ canvas: document.createElement("canvas"), data, backend: "webgpu" })).free();
    }),
    format_is_class: TrisortFormatError.prototype instanceof TrisortError,
    option_is_class: TrisortOptionError.prototype instanceof TrisortError,
  };
  player.free();
  return result;
};
// The package on WebGPU (pkg.mjs opens this page again in a Chromium started with WebGPU):
// `backend: "webgpu"`, frame `frame` read back with readFrame (a WebGPU canvas is not read)
// and compared with the native player's PNG.
window.runWebGpuTest = async ({ file, native, frame }) => {
  const data = await fetchBytes(file);
  const player = await TrisortPlayer.open({
    canvas: document.getElementById("canvas"), data, name: file, backend: "webgpu",
  });
  player.render(frame);
  const read = await player.readFrame(frame);
  const bmp = await createImageBitmap(await (await fetch(native)).blob(), {
    colorSpaceConversion: "none", premultiplyAlpha: "none",
  });
  const { over1, lit } = compare(read, pixels(bmp));
  const result = {
    backend: player.backend, adapter: player.adapter, bytes: read.length,
    pixels: player.width * player.height, lit, over1_native: over1,
  };
  player.free();
  return result;
};
window.packageLoaded = true;
