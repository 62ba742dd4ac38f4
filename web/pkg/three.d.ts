// Types of @trisort/player/three (three.js). three is a peer dependency: `npm install three`.
import * as THREE from "three";
import type { TrisortBake, TrisortPlayer } from "./index.js";

/** The options of `new TrisortMesh(source, options)`. */
export interface TrisortMeshOptions {
  /**
   * `blend` (default): the baked order back to front, the file's materials as one
   * `MeshPhysicalMaterial` with `depthTest: false`, transparent where a material blends.
   * `depth`: front to back with the depth test (a reference, as `trisort play --mode depth`).
   */
  mode?: "blend" | "depth";
  /**
   * Draw each triangle in a flat colour encoding its id + 1 (R = bits 0–7, G = 8–15,
   * B = 16–23; alpha 1; 0 where nothing is drawn) instead of its material: order and
   * visibility checks read pixels without shading in the way. Builds one vertex per corner.
   */
  idColors?: boolean;
  /**
   * After the frame's draws, draw every copy of the file once more (the file's z-buffer twin:
   * with `mode: "depth"`, what the frame must equal wherever it has no hole).
   */
  zbuffer?: boolean;
  /** Names the file in errors when `source` is bytes. */
  name?: string;
}

/** What `setFrame` draws: `[first_index, index_count]` pairs and their WebGL arguments. */
export interface TrisortRanges {
  /** The draws as the native player issues them, in index units. */
  pairs: Uint32Array;
  /** Indices per draw (`multiDrawElementsWEBGL`'s counts). */
  counts: Int32Array;
  /** Byte offsets of the draws into the index buffer. */
  offsets: Int32Array;
}

/**
 * A baked file as a three.js mesh for the app's own `WebGLRenderer` (WebGL2). Its geometry
 * holds the sorted index buffer and the vertex streams (`position`, `normal`, `uv`, and
 * `trisortNode`, `trisortMaterial`: each vertex's node and material). `setFrame(i)` uploads
 * frame i's node matrices (a float data texture) and camera; at render time the mesh draws
 * frame i's ranges over the index buffer in the baked order (`WEBGL_multi_draw`, else one
 * `drawElements` per range). Render the scene with `mesh.camera`: the order is exact only from
 * the frame's own camera, and the mesh ignores its own transform (its matrices are the file's).
 */
export class TrisortMesh extends THREE.Mesh<THREE.BufferGeometry, THREE.Material> {
  /**
   * @param source the file: a `TrisortBake`, a `TrisortPlayer` (its file, decoded again), or
   *   its bytes (after `await initTrisort()`).
   * @throws {import("./index.js").TrisortFormatError} damaged bytes
   * @throws {import("./index.js").TrisortOptionError} an unknown mode; bytes before the wasm loaded
   */
  constructor(source: TrisortBake | TrisortPlayer | Uint8Array | ArrayBuffer | ArrayBufferView,
    options?: TrisortMeshOptions);
  readonly bake: TrisortBake;
  readonly mode: "blend" | "depth";
  readonly idColors: boolean;
  readonly zbuffer: boolean;
  /** Whether the index buffer and the ranges are reversed (back to front: `blend`). */
  readonly backToFront: boolean;
  /** The frame shown (`setFrame`). */
  readonly frame: number;
  readonly frameCount: number;
  /** The frame's camera: the file's view and projection (WebGL clip depth). */
  readonly camera: THREE.PerspectiveCamera;
  /** The file's material factors, 16 floats per material (`TrisortBake.materialFactors`). */
  readonly materialFactors: Float32Array;
  /** The current frame's draws. */
  readonly ranges: TrisortRanges;
  /** `WEBGL_multi_draw` once the mesh has drawn (null: one drawElements per range). */
  readonly multiDraw: object | null | undefined;
  /** Frame `frame`'s draws (cached). */
  frameRanges(frame: number): TrisortRanges;
  /**
   * Shows frame `frame` (0-based): its node matrices, camera and draws.
   * @throws {import("./index.js").TrisortOptionError} a frame outside the file
   */
  setFrame(frame: number): this;
  /** Frees the geometry, material, textures and the decoded file. */
  dispose(): void;
}
