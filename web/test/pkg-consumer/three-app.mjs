// The three.js integration as an app uses it (web/test/pkg.mjs drives it): `TrisortMesh`s in
// three.js scenes drawn by the page's own WebGLRenderer, every frame of the demo bake, in the
// flat id-colour mode (each triangle's id + 1 as RGB, 0 the background), checked
//   1. against itself with the depth test, as the native self-check: the frame's window drawn
//      depth-tested (depth mode) against its z-buffer twin (the window, then every triangle of
//      the file, depth-tested): a pixel that differs is a hole (a triangle the frame leaves out
//      is nearest there). The sorted draw (blend: back to front, no depth test) against the
//      depth-tested draw: pixels that differ are order errors, or this rasterizer's depth
//      test disagreeing with the order recorded on another;
//   2. against plain WebGL2 in the page drawing the same id colours with the player's own
//      draw ranges (the native player's commands, `frame_ranges`), one drawElements per range
//      in order: the order three.js draws must match pixel for pixel.
// Then frame 0 with the file's materials as MeshPhysicalMaterial on the canvas.
// window.runThreeTest(options) returns what the test gates.
import * as THREE from "three";
import { TrisortBake } from "@trisort/player";
import { TrisortMesh } from "@trisort/player/three";

// The same id colours drawn without three.js: de-indexed copies in play order, each frame's
// ranges of the back-to-front buffer as drawElements calls, node matrices in a float texture.
function plainWebGL2(bake, w, h, samples) {
  const canvas = new OffscreenCanvas(w, h);
  const gl = canvas.getContext("webgl2", { antialias: false, depth: false, premultipliedAlpha: false });
  const sh = (type, src) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const prog = gl.createProgram();
  gl.attachShader(prog, sh(gl.VERTEX_SHADER, `#version 300 es
uniform highp sampler2D nodes;
uniform mat4 proj;
in vec3 position; in float node; in float id; in vec2 flags;
flat out float vId; flat out vec2 vFlags;
void main() {
  int i = int(node + 0.5) * 4;
  ivec2 at = ivec2(i % 1024, i / 1024);
  mat4 m = mat4(texelFetch(nodes, at, 0), texelFetch(nodes, at + ivec2(1, 0), 0),
    texelFetch(nodes, at + ivec2(2, 0), 0), texelFetch(nodes, at + ivec2(3, 0), 0));
  gl_Position = proj * (m * vec4(position, 1.0));
  vId = id; vFlags = flags;
}`));
  gl.attachShader(prog, sh(gl.FRAGMENT_SHADER, `#version 300 es
precision highp float;
flat in float vId; flat in vec2 vFlags;
out vec4 color;
void main() {
  if (vFlags.x < 0.5 && !gl_FrontFacing) discard;
  if (vFlags.y > 0.5) discard;
  uint u = uint(vId + 0.5);
  color = vec4(float(u & 255u), float((u >> 8) & 255u), float((u >> 16) & 255u), 255.0) / 255.0;
}`));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  const idx = bake.indices(true), ids = bake.copyTriangles(true), pos = bake.positions();
  const vnode = bake.vertexNodes(), vmat = bake.vertexMaterials(), f = bake.materialFactors();
  const n = idx.length;
  const p = new Float32Array(3 * n), nd = new Float32Array(n), id = new Float32Array(n), fl = new Float32Array(2 * n);
  for (let k = 0; k < n; k++) {
    const v = idx[k], m = vmat[v];
    p.set(pos.subarray(3 * v, 3 * v + 3), 3 * k);
    nd[k] = vnode[v];
    id[k] = ids[(k / 3) | 0] + 1;
    fl[2 * k] = f[16 * m + 11]; // double-sided
    fl[2 * k + 1] = f[16 * m + 9] === 1 && f[16 * m + 3] < f[16 * m + 10] ? 1 : 0; // masked out
  }
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  for (const [name, data, size] of [["position", p, 3], ["node", nd, 1], ["id", id, 1], ["flags", fl, 2]]) {
    const loc = gl.getAttribLocation(prog, name);
    if (loc < 0) continue;
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
  }
  const seq = new Uint32Array(n);
  for (let k = 0; k < n; k++) seq[k] = k;
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, seq, gl.STATIC_DRAW);
  const texels = 4 * Math.max(1, bake.nodeCount), tw = Math.min(1024, Math.max(4, texels));
  const th = Math.ceil(texels / tw);
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.useProgram(prog);
  gl.uniform1i(gl.getUniformLocation(prog, "nodes"), 0);
  gl.viewport(0, 0, w, h);
  gl.disable(gl.DEPTH_TEST);
  gl.disable(gl.CULL_FACE);
  // At the file's sample count (4, as the bake and the native player), resolved by a blit.
  const msaa = gl.createFramebuffer(), rb = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, rb);
  gl.renderbufferStorageMultisample(gl.RENDERBUFFER, samples, gl.RGBA8, w, h);
  gl.bindFramebuffer(gl.FRAMEBUFFER, msaa);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb);
  const resolved = gl.createFramebuffer(), rb1 = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, rb1);
  gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, w, h);
  gl.bindFramebuffer(gl.FRAMEBUFFER, resolved);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb1);
  const out = new Uint8Array(4 * w * h);
  return (frame) => {
    gl.bindFramebuffer(gl.FRAMEBUFFER, msaa);
    const data = new Float32Array(tw * th * 4);
    data.set(bake.nodeViewMatrices(frame));
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, tw, th, 0, gl.RGBA, gl.FLOAT, data);
    const pr = Float32Array.from(bake.projection(frame));
    for (let c = 0; c < 4; c++) pr[4 * c + 2] = Math.fround(2 * pr[4 * c + 2] - pr[4 * c + 3]);
    gl.uniformMatrix4fv(gl.getUniformLocation(prog, "proj"), false, pr);
    gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT);
    const r = bake.frameRanges(frame, true);
    for (let k = 0; k < r.length; k += 2) gl.drawElements(gl.TRIANGLES, r[k + 1], gl.UNSIGNED_INT, 4 * r[k]);
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, msaa);
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, resolved);
    gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.COLOR_BUFFER_BIT, gl.NEAREST);
    gl.bindFramebuffer(gl.FRAMEBUFFER, resolved);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, out);
    return out;
  };
}

// The file's sample count (web/build.sh bakes with --samples 4): its order is exact at the
// samples of a 4x multisampled target. Resolved, a pixel is one id where its samples agree and
// a blend of ids at edges, the same blend in two images whose samples match.
const SAMPLES = Number(new URLSearchParams(location.search).get("samples") ?? 0);
const idAt = (px, i) => (px[4 * i + 3] === 0 ? 0 : px[4 * i] | (px[4 * i + 1] << 8) | (px[4 * i + 2] << 16));

window.runThreeTest = async ({ file, frames }) => {
  const t0 = performance.now();
  const data = new Uint8Array(await (await fetch(file)).arrayBuffer());
  const bake = await TrisortBake.open({ data, name: file });
  const w = bake.width, h = bake.height;
  const canvas = document.getElementById("canvas");
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
  renderer.setPixelRatio(1);
  renderer.setSize(w, h, false);
  renderer.setClearColor(0x000000, 0);
  const target = new THREE.WebGLRenderTarget(w, h, { depthBuffer: true, samples: SAMPLES });
  const sorted = new TrisortMesh(bake, { idColors: true });
  const zbuffer = new TrisortMesh(bake, { idColors: true, mode: "depth", zbuffer: true });
  const sortedScene = new THREE.Scene().add(sorted);
  const zScene = new THREE.Scene().add(zbuffer);
  const depth = new TrisortMesh(bake, { idColors: true, mode: "depth" });
  const dScene = new THREE.Scene().add(depth);
  const plain = plainWebGL2(bake, w, h, SAMPLES);
  const ids = bake.copyTriangles(true);
  const read = (scene, camera) => {
    renderer.setRenderTarget(target);
    renderer.clear();
    renderer.render(scene, camera);
    const px = new Uint8Array(4 * w * h);
    renderer.readRenderTargetPixels(target, 0, 0, w, h, px);
    renderer.setRenderTarget(null);
    return px;
  };
  const list = frames ?? [...Array(bake.frameCount).keys()];
  const rows = [];
  const tSetup = performance.now() - t0;
  for (const f of list) {
    sorted.setFrame(f);
    zbuffer.setFrame(f);
    depth.setFrame(f);
    const a = read(sortedScene, sorted.camera);
    const b = read(zScene, zbuffer.camera);
    const d = read(dScene, depth.camera);
    const c = plain(f);
    // The triangles frame f draws.
    const drawn = new Set();
    const r = sorted.ranges.pairs;
    for (let k = 0; k < r.length; k += 2) {
      for (let i = r[k] / 3; i < (r[k] + r[k + 1]) / 3; i++) drawn.add(ids[i] + 1);
    }
    // holes: the frame's depth-tested draw vs its z-buffer twin's (the native self-check);
    // order errors: the sorted draw vs the frame's depth-tested draw; plain: vs plain WebGL2.
    let holes = 0, orderErrors = 0, plainDiff = 0, covered = 0, zDiff = 0;
    for (let i = 0; i < w * h; i++) {
      const s = idAt(a, i), z = idAt(b, i), dd = idAt(d, i);
      if (s !== 0) covered++;
      if (dd !== z) holes++;
      if (s !== dd) orderErrors++;
      if (s !== z) zDiff++;
      if (s !== idAt(c, i)) plainDiff++;
    }
    rows.push({ frame: f, holes, order_errors: orderErrors, sorted_vs_zbuffer: zDiff, plain_webgl2_diff: plainDiff, covered, draws: r.length / 2 });
  }
  const tFrames = performance.now() - t0 - tSetup;
  // Frame 0 with the file's materials (MeshPhysicalMaterial, three's lighting) on the canvas.
  const pbr = new TrisortMesh(bake);
  const scene = new THREE.Scene().add(pbr);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2));
  const sun = new THREE.DirectionalLight(0xffffff, 2);
  sun.position.set(1, 2, 1);
  scene.add(sun);
  renderer.toneMapping = THREE.NeutralToneMapping;
  pbr.setFrame(0);
  const px = read(scene, pbr.camera);
  let lit = 0;
  for (let i = 0; i < w * h; i++) if (px[4 * i + 3] !== 0) lit++;
  renderer.render(scene, pbr.camera);
  const result = {
    three: THREE.REVISION, width: w, height: h, frames: rows,
    multi_draw: !!sorted.multiDraw, has_multi_draw: !!renderer.getContext().getExtension("WEBGL_multi_draw"),
    pbr_transparent: pbr.material.transparent,
    pbr_material: pbr.material.type, pbr_depth_test: pbr.material.depthTest, pbr_lit: lit,
    ms_setup: tSetup, ms_frames: tFrames,
  };
  for (const m of [sorted, zbuffer, depth]) { m.geometry.dispose(); m.material.dispose(); }
  pbr.dispose();
  renderer.dispose();
  return result;
};
window.threeLoaded = true;
