// Types of @trisort/player (index.js). The wasm-bindgen module underneath has its own
// generated types in wasm/trisort_web.d.ts (`TrisortPlayer.raw`).

/** Which browser graphics API plays the file: WebGPU where offered, else WebGL2 (`auto`). */
export type Backend = "auto" | "webgpu" | "webgl2";
/**
 * How the file is drawn: `blend` (the baked order, alpha blended), `depth` (with a depth
 * test: the self-check's mode), `saturate` (the order's overlap, for inspection).
 */
export type Mode = "blend" | "depth" | "saturate";
/** The shading model, as `trisort play --shading`. */
export type Shading = "pbr" | "basic";
/** The tone map, as `trisort play --tonemap`. */
export type ToneMap = "neutral" | "aces";
/** Where the wasm module comes from when not next to index.js. */
export type WasmSource = string | URL | Request | Response | BufferSource | WebAssembly.Module;

/** The options of `TrisortPlayer.open`. */
export interface OpenOptions {
  /** The canvas to draw on; it is sized to the file's recorded size. */
  canvas: HTMLCanvasElement;
  /** The baked file's bytes (a `.baked` file fetched or read by the app). */
  data: Uint8Array | ArrayBuffer | ArrayBufferView;
  /** Names the file in error messages (default "baked file"). */
  name?: string;
  /** Default "auto". */
  backend?: Backend;
  /** Default "blend". */
  mode?: Mode;
  /** Default "pbr". */
  shading?: Shading;
  /** Default "neutral". */
  tonemap?: ToneMap;
  /**
   * Play the file's z-buffer twin (each frame's window, then every triangle) instead: in
   * `depth` mode it differs from the file's frame only at holes (a self-check).
   */
  zbuffer?: boolean;
  /** The `.wasm` to load on first use (default: `wasm/trisort_web_bg.wasm` beside index.js). */
  wasm?: WasmSource;
}

/** One clip (camera path) of the file: frames `first .. first + count`, at `fps` if known. */
export interface Clip {
  name: string;
  first: number;
  count: number;
  fps: number | undefined;
}

/** What a frame draws. */
export interface FrameStats {
  triangles: number;
  draws: number;
}

/** The `code` of a `TrisortError`. */
export type TrisortErrorCode = "format" | "device" | "option";

/** Every error this package throws (and rejects with). */
export class TrisortError extends Error {
  readonly code: TrisortErrorCode;
  /** The wasm's own error, where there was one. */
  readonly cause?: unknown;
}
/** The bytes are not a baked file this player reads: damaged, cut short, another version. */
export class TrisortFormatError extends TrisortError {
  readonly code: "format";
}
/** The browser's graphics: no WebGPU adapter, no context for the canvas, a GPU error. */
export class TrisortDeviceError extends TrisortError {
  readonly code: "device";
}
/** An option or name the caller chose: unknown backend, mode, clip, variant; no canvas. */
export class TrisortOptionError extends TrisortError {
  readonly code: "option";
}

/** Loads the wasm module once (`open` calls it); resolves when it is ready. */
export function initTrisort(wasm?: WasmSource): Promise<unknown>;

/** A baked file playing on a canvas. */
export class TrisortPlayer {
  private constructor();
  /**
   * Decodes the file, sizes the canvas and opens a device on it.
   * @throws {TrisortOptionError} an unknown option value, no canvas, data of another type
   * @throws {TrisortFormatError} a damaged, truncated or unsupported file
   * @throws {TrisortDeviceError} no WebGPU/WebGL2 for the canvas, a device that cannot play it
   */
  static open(options: OpenOptions): Promise<TrisortPlayer>;
  /** Draws `frame` (0-based) and presents it; returns the milliseconds spent encoding it. */
  render(frame: number): number;
  /**
   * Draws `frame` off-screen and reads it back through a mapped buffer (the canvas is
   * untouched): `width × height` RGBA texels, rows top to bottom, 8-bit sRGB with alpha 255,
   * converted as the native player converts its PNG frames. Works on WebGPU, whose canvases
   * cannot be read back in every browser, and on WebGL2. Await one read before the next.
   * @throws {TrisortOptionError} a read while the previous one has not settled
   * @throws {TrisortDeviceError} the device failed to draw or map the frame
   */
  readFrame(frame: number): Promise<Uint8Array>;
  readonly frameCount: number;
  readonly width: number;
  readonly height: number;
  /** The path's frame rate as baked, where the file says. */
  readonly fps: number | undefined;
  /** "WebGPU" or "WebGL2". */
  readonly backend: string;
  readonly adapter: string;
  readonly warnings: string[];
  /** The raster profile the file was baked for (`exact`, `conformant`, `snap4`, `browser`). */
  readonly rasterProfile: string;
  frameStats(frame: number): FrameStats;
  /** The line the demo page shows under the canvas for `frame`. */
  figures(frame: number, ms?: number): string;
  /** The file's clips, in frame order (at least one). */
  clips(): Clip[];
  /** The selected clip's name. */
  readonly clip: string;
  /** @throws {TrisortOptionError} an unknown clip (the message lists the clips) */
  setClip(name: string): void;
  /** The frame after (`by` 1) or before (-1) `frame`, looping within the selected clip. */
  step(frame: number, by?: 1 | -1): number;
  /** The file's material variants, including those the bake refuses. */
  variants(): string[];
  /**
   * Plays variant `name`'s materials from the next frame (null or "": the defaults).
   * @throws {TrisortOptionError} an unknown variant, or one that would change visibility
   */
  setVariant(name: string | null): void;
  /** The wasm-bindgen object underneath (its API may change between versions). */
  readonly raw: import("./wasm/trisort_web.js").WebPlayer;
  /** The file as a device-free `TrisortBake` (what `TrisortMesh` is built from). */
  bake(): TrisortBake;
  /** Frees the GPU resources; the player cannot be used afterwards. */
  free(): void;
}

/** The options of `TrisortBake.open`. */
export interface BakeOptions {
  data: Uint8Array | ArrayBuffer | ArrayBufferView;
  /** Names the file in error messages (default "baked file"). */
  name?: string;
  wasm?: WasmSource;
}

/**
 * A baked file decoded without a device: the typed arrays an app's own renderer draws it from.
 * Each method returns a fresh copy. Layouts (README § Web player, "What a JS app gets"):
 * vertex streams per vertex, the index buffer 3 per copy, ranges `[first_index, index_count]`
 * in index units, matrices column-major 16 floats, materials 16 floats each.
 */
export class TrisortBake {
  private constructor();
  /**
   * Loads the wasm module if needed and decodes the file.
   * @throws {TrisortFormatError} a damaged, truncated or unsupported file
   */
  static open(options: BakeOptions): Promise<TrisortBake>;
  /**
   * Decodes the file synchronously (the wasm module must be loaded: `await initTrisort()`).
   * @throws {TrisortFormatError} a damaged, truncated or unsupported file
   * @throws {TrisortOptionError} the wasm module is not loaded yet
   */
  static fromBytes(data: Uint8Array | ArrayBuffer | ArrayBufferView, name?: string): TrisortBake;
  readonly frameCount: number;
  /** The recorded size (the projection's aspect is width / height). */
  readonly width: number;
  readonly height: number;
  readonly vertexCount: number;
  /** Distinct triangles: ids `0 .. triangleCount`. */
  readonly triangleCount: number;
  /** Triangles in the sorted index buffer (a triangle may have several copies). */
  readonly copyCount: number;
  readonly nodeCount: number;
  readonly materialCount: number;
  /** xyz per vertex, in its node's local space. */
  positions(): Float32Array;
  /** Unit normal per vertex, in its node's local space. */
  normals(): Float32Array;
  /** TEXCOORD_0 per vertex. */
  uvs(): Float32Array;
  /** The node moving each vertex. */
  vertexNodes(): Uint32Array;
  /** Each vertex's material. */
  vertexMaterials(): Uint32Array;
  /** The sorted index buffer, 3 per copy: back to front (default, `blend`) or as stored. */
  indices(backToFront?: boolean): Uint32Array;
  /** The triangle id of each copy of `indices(backToFront)`. */
  copyTriangles(backToFront?: boolean): Uint32Array;
  /** Frame `frame`'s draws over `indices(backToFront)`: `[first_index, index_count]` pairs. */
  frameRanges(frame: number, backToFront?: boolean): Uint32Array;
  /** Frame `frame`'s node matrices (view × world), 16 per node, column-major. */
  nodeViewMatrices(frame: number): Float32Array;
  /** Frame `frame`'s projection, column-major, clip depth [0, 1] (wgpu's). */
  projection(frame: number): Float32Array;
  /** Frame `frame`'s view (world → view) matrix in f64, column-major. */
  view(frame: number): Float64Array;
  /** Frame `frame`'s `[yfov, znear, zfar]` (zfar 0: infinite). */
  cameraLens(frame: number): Float64Array;
  /**
   * 16 floats per material: base colour RGBA, emissive RGB, metallic, roughness, alpha mode
   * (0 opaque, 1 mask, 2 blend), alpha cutoff, double-sided, transmission, played opacity,
   * clearcoat, clearcoat roughness.
   */
  materialFactors(): Float32Array;
  materialName(material: number): string;
  readonly raw: import("./wasm/trisort_web.js").BakedData;
  free(): void;
}
