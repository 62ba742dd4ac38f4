// @trisort/player/three: a baked file as a three.js mesh drawn by the app's own
// WebGLRenderer. Types: three.d.ts; README § Web player says what is exact and what differs.
//
// How it draws: one BufferGeometry holds the file's sorted index buffer (reversed copy by copy
// for `blend`, as the native player plays it) and its vertex streams; the node of each vertex
// is an attribute, each frame's node matrices (view × world, from the wasm, in f64 then f32) a
// float data texture the vertex shader reads. three.js draws a mesh as one range (drawRange or
// geometry.groups, one draw per group and material) and keeps its multi-draw for BatchedMesh,
// whose per-instance layout does not fit one sorted index buffer; so the geometry's drawRange
// is empty and `onAfterRender`, with three's program, uniforms and vertex array still bound,
// issues the frame's ranges through WebGL2's WEBGL_multi_draw (one call), or one
// drawElements per range where the extension is missing.
import * as THREE from "three";
import { TrisortBake, TrisortPlayer, TrisortOptionError } from "./index.js";

const ROW = 1024; // texels per row of the node and material textures (a multiple of 4)

function floatTexture(texels) {
  const width = Math.min(ROW, Math.max(4, texels));
  const height = Math.max(1, Math.ceil(texels / width));
  const t = new THREE.DataTexture(new Float32Array(width * height * 4), width, height,
    THREE.RGBAFormat, THREE.FloatType);
  t.minFilter = THREE.NearestFilter;
  t.magFilter = THREE.NearestFilter;
  t.generateMipmaps = false;
  t.needsUpdate = true;
  return t;
}

// The GLSL both materials share: a node's matrix and a material's 4 texels by index.
const FETCH = /* glsl */ `
uniform highp sampler2D trisortNodes;
uniform highp sampler2D trisortMaterials;
uniform mat4 trisortProjection;
mat4 trisortNodeMatrix(float node) {
  int i = int(node + 0.5) * 4;
  ivec2 at = ivec2(i % ${ROW}, i / ${ROW});
  return mat4(texelFetch(trisortNodes, at, 0), texelFetch(trisortNodes, at + ivec2(1, 0), 0),
    texelFetch(trisortNodes, at + ivec2(2, 0), 0), texelFetch(trisortNodes, at + ivec2(3, 0), 0));
}
vec4 trisortMaterialTexel(float m, int k) {
  int i = int(m + 0.5) * 4 + k;
  return texelFetch(trisortMaterials, ivec2(i % ${ROW}, i / ${ROW}), 0);
}
`;

/** A baked file as a three.js mesh; see three.d.ts. */
export class TrisortMesh extends THREE.Mesh {
  constructor(source, options = {}) {
    const bake = source instanceof TrisortBake ? source
      : source instanceof TrisortPlayer ? source.bake()
      : TrisortBake.fromBytes(source, options.name);
    const mode = options.mode ?? "blend";
    if (mode !== "blend" && mode !== "depth") {
      throw new TrisortOptionError(`mode: '${mode}' is not one of blend, depth`);
    }
    super(new THREE.BufferGeometry(), undefined);
    this.type = "TrisortMesh";
    this.bake = bake;
    this.mode = mode;
    this.idColors = !!options.idColors;
    this.zbuffer = !!options.zbuffer;
    this.frame = -1;
    this.frustumCulled = false;
    /** The frame's camera (the file's view and projection): render the scene with it. */
    this.camera = new THREE.PerspectiveCamera();
    this.camera.matrixAutoUpdate = false;
    const backToFront = mode === "blend";
    this.backToFront = backToFront;
    this.uniforms = {
      trisortNodes: { value: floatTexture(4 * Math.max(1, bake.nodeCount)) },
      trisortMaterials: { value: floatTexture(4 * Math.max(1, bake.materialCount)) },
      trisortProjection: { value: new THREE.Matrix4() },
    };
    const factors = bake.materialFactors();
    this.uniforms.trisortMaterials.value.image.data.set(factors);
    this.materialFactors = factors;
    this.geometry = this.#buildGeometry();
    this.material = this.idColors ? this.#idMaterial() : this.#physicalMaterial(factors);
    this.rangeCache = new Map();
    this.setFrame(0);
  }

  #buildGeometry() {
    const bake = this.bake;
    const g = new THREE.BufferGeometry();
    const indices = bake.indices(this.backToFront);
    const pos = bake.positions();
    const node = Float32Array.from(bake.vertexNodes());
    const mat = Float32Array.from(bake.vertexMaterials());
    if (!this.idColors) {
      g.setAttribute("position", new THREE.BufferAttribute(pos, 3));
      g.setAttribute("normal", new THREE.BufferAttribute(bake.normals(), 3));
      g.setAttribute("uv", new THREE.BufferAttribute(bake.uvs(), 2));
      g.setAttribute("trisortNode", new THREE.BufferAttribute(node, 1));
      g.setAttribute("trisortMaterial", new THREE.BufferAttribute(mat, 1));
      const small = bake.vertexCount <= 65536;
      g.setIndex(new THREE.BufferAttribute(small ? Uint16Array.from(indices) : indices, 1));
      this.indexBytes = small ? 2 : 4;
    } else {
      // One vertex per corner of each copy (a triangle's id cannot ride on shared vertices):
      // the index buffer is 0, 1, 2, ... so the frame's ranges apply unchanged.
      const ids = bake.copyTriangles(this.backToFront);
      const n = indices.length;
      const p = new Float32Array(n * 3), nd = new Float32Array(n), m = new Float32Array(n);
      const id = new Float32Array(n);
      for (let k = 0; k < n; k++) {
        const v = indices[k];
        p[3 * k] = pos[3 * v]; p[3 * k + 1] = pos[3 * v + 1]; p[3 * k + 2] = pos[3 * v + 2];
        nd[k] = node[v]; m[k] = mat[v]; id[k] = ids[(k / 3) | 0] + 1;
      }
      g.setAttribute("position", new THREE.BufferAttribute(p, 3));
      g.setAttribute("trisortNode", new THREE.BufferAttribute(nd, 1));
      g.setAttribute("trisortMaterial", new THREE.BufferAttribute(m, 1));
      g.setAttribute("trisortId", new THREE.BufferAttribute(id, 1));
      const seq = new Uint32Array(n);
      for (let k = 0; k < n; k++) seq[k] = k;
      g.setIndex(new THREE.BufferAttribute(seq, 1));
      this.indexBytes = 4;
    }
    this.indexCount = indices.length;
    // three draws nothing itself (an empty range); onAfterRender draws the frame's ranges.
    g.setDrawRange(0, 0);
    return g;
  }

  #depthState(material) {
    const depth = this.mode === "depth";
    material.depthTest = depth;
    material.depthWrite = depth;
    material.depthFunc = THREE.LessDepth; // as the native player's depth mode
    material.side = THREE.DoubleSide; // single-sided materials discard back faces themselves
    material.forceSinglePass = true;
  }

  #physicalMaterial(f) {
    let blends = false;
    for (let m = 0; m < f.length / 16; m++) if (f[16 * m + 13] < 1 || f[16 * m + 9] === 2) blends = true;
    const material = new THREE.MeshPhysicalMaterial({ transparent: blends && this.mode === "blend" });
    this.#depthState(material);
    const uniforms = this.uniforms;
    material.onBeforeCompile = (shader) => {
      Object.assign(shader.uniforms, uniforms);
      shader.vertexShader = shader.vertexShader
        .replace("#include <common>", `#include <common>
${FETCH}
attribute float trisortNode;
attribute float trisortMaterial;
flat varying vec4 vTrisortBase;
flat varying vec4 vTrisortEmissive;
flat varying vec4 vTrisortPbr;
flat varying vec4 vTrisortAlpha;`)
        .replace("#include <defaultnormal_vertex>", `
mat4 trisortNV = trisortNodeMatrix(trisortNode);
vec3 transformedNormal = transpose(inverse(mat3(trisortNV))) * objectNormal;
vTrisortBase = trisortMaterialTexel(trisortMaterial, 0);
vec4 trisortM1 = trisortMaterialTexel(trisortMaterial, 1);
vec4 trisortM2 = trisortMaterialTexel(trisortMaterial, 2);
vec4 trisortM3 = trisortMaterialTexel(trisortMaterial, 3);
vTrisortEmissive = vec4(trisortM1.xyz, 0.0);
vTrisortPbr = vec4(trisortM1.w, trisortM2.x, trisortM3.x, 0.0);
vTrisortAlpha = vec4(trisortM2.y, trisortM2.z, trisortM2.w, trisortM3.y);`)
        .replace("#include <project_vertex>", `
vec4 mvPosition = trisortNV * vec4(transformed, 1.0);
gl_Position = trisortProjection * mvPosition;`);
      shader.fragmentShader = shader.fragmentShader
        .replace("#include <common>", `#include <common>
flat varying vec4 vTrisortBase;
flat varying vec4 vTrisortEmissive;
flat varying vec4 vTrisortPbr;
flat varying vec4 vTrisortAlpha;`)
        .replace("#include <clipping_planes_fragment>", `#include <clipping_planes_fragment>
if (vTrisortAlpha.z < 0.5 && !gl_FrontFacing) discard;
if (vTrisortAlpha.x == 1.0 && vTrisortBase.a < vTrisortAlpha.y) discard;`)
        .replace("#include <color_fragment>", `#include <color_fragment>
diffuseColor = vec4(vTrisortBase.rgb, vTrisortAlpha.w);`)
        .replace("#include <metalnessmap_fragment>", "float metalnessFactor = vTrisortPbr.x;")
        .replace("#include <roughnessmap_fragment>", "float roughnessFactor = vTrisortPbr.y;")
        .replace("#include <emissivemap_fragment>", "totalEmissiveRadiance = vTrisortEmissive.rgb;");
    };
    material.customProgramCacheKey = () => "trisort-physical";
    return material;
  }

  #idMaterial() {
    const material = new THREE.ShaderMaterial({
      glslVersion: THREE.GLSL3,
      uniforms: this.uniforms,
      vertexShader: `${FETCH}
in float trisortNode;
in float trisortMaterial;
in float trisortId;
flat out float vId;
flat out vec4 vAlpha;
flat out float vBaseAlpha;
void main() {
  gl_Position = trisortProjection * (trisortNodeMatrix(trisortNode) * vec4(position, 1.0));
  vId = trisortId;
  vAlpha = trisortMaterialTexel(trisortMaterial, 2);
  vBaseAlpha = trisortMaterialTexel(trisortMaterial, 0).a;
}`,
      fragmentShader: `
layout(location = 0) out highp vec4 trisortColor;
flat in float vId;
flat in vec4 vAlpha;
flat in float vBaseAlpha;
void main() {
  if (vAlpha.w < 0.5 && !gl_FrontFacing) discard;
  if (vAlpha.y == 1.0 && vBaseAlpha < vAlpha.z) discard;
  uint u = uint(vId + 0.5);
  trisortColor = vec4(float(u & 255u), float((u >> 8) & 255u), float((u >> 16) & 255u), 255.0) / 255.0;
}`,
    });
    this.#depthState(material);
    return material;
  }

  /** Frames in the file. */
  get frameCount() { return this.bake.frameCount; }

  /** The draws of `frame` as `[first_index, index_count]` pairs (cached). */
  frameRanges(frame) {
    let r = this.rangeCache.get(frame);
    if (!r) {
      const pairs = this.bake.frameRanges(frame, this.backToFront);
      const n = pairs.length / 2 + (this.zbuffer ? 1 : 0);
      const counts = new Int32Array(n), offsets = new Int32Array(n);
      for (let k = 0; k < pairs.length / 2; k++) {
        offsets[k] = pairs[2 * k] * this.indexBytes;
        counts[k] = pairs[2 * k + 1];
      }
      // The z-buffer twin (depth mode): then every copy of the file, as the native self-check.
      if (this.zbuffer) { offsets[n - 1] = 0; counts[n - 1] = this.indexCount; }
      r = { counts, offsets, pairs };
      this.rangeCache.set(frame, r);
    }
    return r;
  }

  /** Shows frame `frame`: its node matrices, its camera (`mesh.camera`) and its draws. */
  setFrame(frame) {
    const bake = this.bake;
    if (!(frame >= 0 && frame < bake.frameCount)) {
      throw new TrisortOptionError(`frame ${frame} is outside 0..${bake.frameCount - 1}`);
    }
    // The frame shown already: its matrices are uploaded (render loops call this each tick).
    if (frame === this.frame) return this;
    this.frame = frame;
    const nodes = this.uniforms.trisortNodes.value;
    nodes.image.data.set(bake.nodeViewMatrices(frame));
    nodes.needsUpdate = true;
    // wgpu's clip depth [0, 1] to WebGL's [-1, 1]: z' = 2z - w (x, y and w unchanged).
    const p = bake.projection(frame);  // a fresh Float32Array
    for (let c = 0; c < 4; c++) p[4 * c + 2] = Math.fround(2 * p[4 * c + 2] - p[4 * c + 3]);
    this.uniforms.trisortProjection.value.fromArray(p);
    const cam = this.camera;
    cam.matrix.fromArray(bake.view(frame)).invert();
    cam.updateMatrixWorld(true);
    cam.projectionMatrix.fromArray(p);
    cam.projectionMatrixInverse.copy(cam.projectionMatrix).invert();
    this.ranges = this.frameRanges(frame);
    return this;
  }

  /** Draws the frame's ranges with three's program and vertex array still bound. */
  onAfterRender(renderer) {
    const gl = renderer.getContext();
    const { counts, offsets } = this.ranges;
    const type = this.indexBytes === 2 ? gl.UNSIGNED_SHORT : gl.UNSIGNED_INT;
    if (this.multiDraw === undefined) {
      this.multiDraw = renderer.extensions.get("WEBGL_multi_draw") || null;
    }
    if (counts.length === 0) return;
    if (this.multiDraw) {
      this.multiDraw.multiDrawElementsWEBGL(gl.TRIANGLES, counts, 0, type, offsets, 0, counts.length);
    } else {
      for (let k = 0; k < counts.length; k++) gl.drawElements(gl.TRIANGLES, counts[k], type, offsets[k]);
    }
  }

  /** Frees the geometry, material and textures (and the decoded file). */
  dispose() {
    this.geometry.dispose();
    this.material.dispose();
    this.uniforms.trisortNodes.value.dispose();
    this.uniforms.trisortMaterials.value.dispose();
    this.bake.free();
  }
}
