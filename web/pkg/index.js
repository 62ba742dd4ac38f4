// @trisort/player: trisort's web player as an ES module with an options-object API and typed
// errors, over the wasm-bindgen module in wasm/ (built by web/build.sh). Types: index.d.ts.
import init, { WebPlayer, BakedData } from "./wasm/trisort_web.js";

/** Every error this package throws; `code` says which kind (`format`, `device`, `option`). */
export class TrisortError extends Error {
  constructor(message, code, options) {
    super(message, options);
    this.name = "TrisortError";
    this.code = code;
  }
}

/** The bytes are not a baked file this player reads: damaged, cut short, another version. */
export class TrisortFormatError extends TrisortError {
  constructor(message, options) {
    super(message, "format", options);
    this.name = "TrisortFormatError";
  }
}

/** The browser's graphics: no WebGPU adapter, no context for the canvas, a GPU error. */
export class TrisortDeviceError extends TrisortError {
  constructor(message, options) {
    super(message, "device", options);
    this.name = "TrisortDeviceError";
  }
}

/** An option or name the caller chose: unknown backend, mode, clip, variant, missing canvas. */
export class TrisortOptionError extends TrisortError {
  constructor(message, options) {
    super(message, "option", options);
    this.name = "TrisortOptionError";
  }
}

const CLASSES = { format: TrisortFormatError, device: TrisortDeviceError, option: TrisortOptionError };

// The wasm throws JS Errors with a `kind` property (web/src/browser.rs, ErrorKind); anything
// else (a panic's RuntimeError, a browser exception) is a device error with the original as
// its cause.
function wrap(e) {
  if (e instanceof TrisortError) return e;
  const Class = (e && CLASSES[e.kind]) || TrisortDeviceError;
  const message = e && typeof e.message === "string" ? e.message : String(e);
  return new Class(message, { cause: e });
}

function call(f) {
  try {
    return f();
  } catch (e) {
    throw wrap(e);
  }
}

const BACKENDS = ["auto", "webgpu", "webgl2"];
const MODES = ["blend", "depth", "saturate"];
const SHADINGS = ["pbr", "basic"];
const TONEMAPS = ["neutral", "aces"];

function choice(options, key, allowed, fallback) {
  const v = options[key] ?? fallback;
  if (!allowed.includes(v)) {
    throw new TrisortOptionError(`${key}: '${v}' is not one of ${allowed.join(", ")}`);
  }
  return v;
}

function bytesOf(data) {
  if (data instanceof Uint8Array) return data;
  if (data instanceof ArrayBuffer) return new Uint8Array(data);
  if (ArrayBuffer.isView(data)) return new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  throw new TrisortOptionError("data: expected a Uint8Array, an ArrayBuffer or another ArrayBufferView");
}

let ready = null;
let loaded = false;

/**
 * Loads the wasm module once (later calls return the same promise). `open` calls it; call it
 * yourself to load early or to load the `.wasm` from elsewhere (a URL, a Response, a
 * WebAssembly.Module).
 */
export function initTrisort(wasm) {
  if (!ready) {
    ready = init(wasm === undefined ? undefined : { module_or_path: wasm }).then((m) => {
      loaded = true;
      return m;
    }, (e) => {
      ready = null;
      throw new TrisortDeviceError(`loading the trisort wasm module: ${e && e.message ? e.message : e}`, { cause: e });
    });
  }
  return ready;
}

/** A baked file playing on a canvas. Make one with `await TrisortPlayer.open({ ... })`. */
export class TrisortPlayer {
  #raw;
  #source;

  constructor(raw, source = null) {
    if (!(raw instanceof WebPlayer)) {
      throw new TrisortOptionError("use `await TrisortPlayer.open({ canvas, data })`");
    }
    this.#raw = raw;
    this.#source = source;
  }

  /** Opens `options.data` (a baked file's bytes) on `options.canvas`; see index.d.ts. */
  static async open(options) {
    if (!options || typeof options !== "object") {
      throw new TrisortOptionError("open: expected an options object { canvas, data, ... }");
    }
    const { canvas } = options;
    if (typeof HTMLCanvasElement === "undefined" || !(canvas instanceof HTMLCanvasElement)) {
      throw new TrisortOptionError("canvas: expected an HTMLCanvasElement");
    }
    const bytes = bytesOf(options.data);
    const name = String(options.name ?? "baked file");
    const backend = choice(options, "backend", BACKENDS, "auto");
    const mode = choice(options, "mode", MODES, "blend");
    const shading = choice(options, "shading", SHADINGS, "pbr");
    const tonemap = choice(options, "tonemap", TONEMAPS, "neutral");
    await initTrisort(options.wasm);
    try {
      const raw = await WebPlayer.open(canvas, bytes, name, backend, mode, !!options.zbuffer, shading, tonemap);
      return new TrisortPlayer(raw, { bytes, name });
    } catch (e) {
      throw wrap(e);
    }
  }

  /** Draws `frame` (0-based, among the file's frames) on the canvas; returns the ms spent. */
  render(frame) {
    const t0 = performance.now();
    call(() => this.#raw.render(frame));
    return performance.now() - t0;
  }

  /**
   * Frame `frame` drawn off-screen and read back through a mapped buffer: width × height RGBA
   * texels, rows top to bottom, 8-bit sRGB, alpha 255 (the native player's PNG pixels). The
   * canvas is untouched. One read at a time; see index.d.ts.
   */
  async readFrame(frame) {
    try {
      return await this.#raw.read_frame(frame);
    } catch (e) {
      throw wrap(e);
    }
  }

  /** Frames in the file. */
  get frameCount() { return this.#raw.frame_count(); }
  /** The canvas size, the recorded size. */
  get width() { return this.#raw.width(); }
  get height() { return this.#raw.height(); }
  /** The path's frame rate as baked, or undefined. */
  get fps() { return this.#raw.fps(); }
  /** "WebGPU" or "WebGL2". */
  get backend() { return this.#raw.backend(); }
  /** The adapter as the browser names it. */
  get adapter() { return this.#raw.adapter(); }
  /** What makes this playback inexact (another device than the recording's, ...). */
  get warnings() { return this.#raw.warnings(); }
  /** The raster profile the file was baked for. */
  get rasterProfile() { return this.#raw.raster_profile(); }

  /** Triangles and draw calls frame `frame` issues. */
  frameStats(frame) {
    return { triangles: this.#raw.frame_triangles(frame), draws: this.#raw.frame_draws(frame) };
  }

  /** The figures line for `frame` drawn in `ms` ("frame 1/48 · 37,126 triangles · ..."). */
  figures(frame, ms = 0) { return this.#raw.figures(frame, ms); }

  /** The file's clips (camera paths), in frame order, each with its frames and rate. */
  clips() {
    return this.#raw.clips().map((name) => {
      const [first, count] = this.#raw.clip_range(name);
      return { name, first, count, fps: this.#raw.clip_fps(name) };
    });
  }

  /** The selected clip's name (the first clip until `setClip`). */
  get clip() { return this.#raw.clip(); }

  /** Selects clip `name`; `step` then loops within its frames. TrisortOptionError if unknown. */
  setClip(name) { call(() => this.#raw.set_clip(name)); }

  /** The frame after (+1) or before (-1) `frame` within the selected clip, looping. */
  step(frame, by = 1) { return this.#raw.step_frame(frame, by); }

  /** The file's material variants (KHR_materials_variants). */
  variants() { return this.#raw.variants(); }

  /** Plays variant `name`'s materials from the next frame (null or "": the defaults). */
  setVariant(name) { call(() => this.#raw.set_variant(name ?? "")); }

  /** The wasm-bindgen object underneath (its API may change between versions). */
  get raw() { return this.#raw; }

  /**
   * The file this player plays as a device-free `TrisortBake` (decoded again from the bytes
   * `open` was given): what `new TrisortMesh(...)` (`@trisort/player/three`) is built from.
   */
  bake() {
    if (!this.#source) throw new TrisortOptionError("this player was freed");
    return TrisortBake.fromBytes(this.#source.bytes, this.#source.name);
  }

  /** Frees the player's GPU resources; the player cannot be used afterwards. */
  free() {
    if (this.#raw) {
      this.#raw.free();
      this.#raw = null;
      this.#source = null;
    }
  }
}

/**
 * A baked file decoded without a device: the typed arrays an app's own renderer draws it from
 * (README § Web player, "What a JS app gets"). `await TrisortBake.open({ data })`, or
 * `TrisortBake.fromBytes(data)` once `initTrisort()` has resolved.
 */
export class TrisortBake {
  #raw;

  constructor(raw) {
    if (!(raw instanceof BakedData)) {
      throw new TrisortOptionError("use `await TrisortBake.open({ data })` or `TrisortBake.fromBytes(data)`");
    }
    this.#raw = raw;
  }

  /** Loads the wasm module if needed and decodes `options.data` (`name` names it in errors). */
  static async open(options) {
    if (!options || typeof options !== "object") {
      throw new TrisortOptionError("open: expected an options object { data, ... }");
    }
    const bytes = bytesOf(options.data);
    await initTrisort(options.wasm);
    return TrisortBake.fromBytes(bytes, options.name);
  }

  /** Decodes `data` synchronously; the wasm module must be loaded (`await initTrisort()`). */
  static fromBytes(data, name = "baked file") {
    const bytes = bytesOf(data);
    if (!loaded) {
      throw new TrisortOptionError("the wasm module is not loaded yet: await initTrisort() (or use TrisortBake.open)");
    }
    return new TrisortBake(call(() => BakedData.open(bytes, String(name))));
  }

  get frameCount() { return this.#raw.frame_count(); }
  get width() { return this.#raw.width(); }
  get height() { return this.#raw.height(); }
  get vertexCount() { return this.#raw.vertex_count(); }
  get triangleCount() { return this.#raw.triangle_count(); }
  get copyCount() { return this.#raw.copy_count(); }
  get nodeCount() { return this.#raw.node_count(); }
  get materialCount() { return this.#raw.material_count(); }
  positions() { return this.#raw.positions(); }
  normals() { return this.#raw.normals(); }
  uvs() { return this.#raw.uvs(); }
  vertexNodes() { return this.#raw.vertex_nodes(); }
  vertexMaterials() { return this.#raw.vertex_materials(); }
  indices(backToFront = true) { return this.#raw.indices(backToFront); }
  copyTriangles(backToFront = true) { return this.#raw.copy_triangles(backToFront); }
  frameRanges(frame, backToFront = true) { return this.#raw.frame_ranges(frame, backToFront); }
  nodeViewMatrices(frame) { return this.#raw.node_view_matrices(frame); }
  projection(frame) { return this.#raw.projection(frame); }
  view(frame) { return this.#raw.view(frame); }
  cameraLens(frame) { return this.#raw.camera_lens(frame); }
  materialFactors() { return this.#raw.material_factors(); }
  materialName(m) { return this.#raw.material_name(m); }

  /** The wasm-bindgen object underneath (its API may change between versions). */
  get raw() { return this.#raw; }

  /** Frees the decoded file. */
  free() {
    if (this.#raw) {
      this.#raw.free();
      this.#raw = null;
    }
  }
}
