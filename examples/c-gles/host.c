/*
 * A host in C: plays a trisort baked file with OpenGL ES 3.0 through EGL (no window), with its
 * own small shaders, one glDrawElements per range, and writes each frame as a PNG.
 *
 *   host BAKED OUT_DIR [blend|depth|saturate] [--shading basic|pbr] [--shaders DIR]
 *        [--clip NAME]
 *
 * `--shading basic` (the default) draws with this file's own small shaders (one light plus
 * ambient); `--shading pbr` draws with the player's own shaders as `trisort export-shaders
 * --lang glsl-es-300 -o DIR` writes them (physically based, lit by the file's environment,
 * tone mapped), loaded from DIR, fed the bytes the player uploads (trisort_gpu_*()).
 * `--clip NAME` draws only the frames of the clip (camera path) of that name; frame numbers
 * (and the PNG names) stay the file's. Without it every frame of every clip is drawn.
 *
 * Frames are drawn at the size and MSAA sample count the file was recorded at, into a linear
 * RGBA16F target, and quantized once to 8-bit sRGB as trisort's own player does; so on the same
 * driver they match `trisort play --backend gl` closely (tests/c_host.rs measures how closely).
 * Plain C99; links the trisort C API (capi/include/trisort.h), libEGL and libGLESv2 only.
 * Build: see examples/c-gles/README.md.
 */
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trisort.h"

/* The view-space light and background of trisort's pipelines (gpu/src/scene_gpu.rs LIGHT,
 * gpu/src/target.rs BACKGROUND). */
static const float LIGHT[4] = {-0.3f, 0.6f, 0.75f, 0.35f};
static const float BACKGROUND[3] = {0.03f, 0.03f, 0.03f};

static void die(const char *what) {
    fprintf(stderr, "host: error: %s\n", what);
    exit(1);
}

/* Exits with the library's message when a trisort call failed. */
static void check(TrisortStatus s, const char *call) {
    if (s != TRISORT_STATUS_OK) {
        char msg[1024];
        trisort_last_error(msg, sizeof msg);
        fprintf(stderr, "host: error: %s failed (status %d): %s\n", call, (int)s, msg);
        exit(1);
    }
}

static void check_gl(const char *where) {
    GLenum e = glGetError();
    if (e != GL_NO_ERROR) {
        fprintf(stderr, "host: error: GL error 0x%x at %s\n", (unsigned)e, where);
        exit(1);
    }
}

static void *xmalloc(size_t n) {
    void *p = malloc(n ? n : 1);
    if (!p) die("out of memory");
    return p;
}

/* ---- PNG (8-bit RGBA, zlib stored blocks: no compression library needed) ---- */

static uint32_t crc_table[256];

static void crc_init(void) {
    uint32_t n, k;
    for (n = 0; n < 256; n++) {
        uint32_t c = n;
        for (k = 0; k < 8; k++) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc_update(uint32_t c, const unsigned char *p, size_t n) {
    while (n--) c = crc_table[(c ^ *p++) & 0xff] ^ (c >> 8);
    return c;
}

static void put32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

static void chunk(FILE *f, const char *type, const unsigned char *data, uint32_t len) {
    unsigned char b[4];
    uint32_t c;
    put32(b, len);
    fwrite(b, 1, 4, f);
    fwrite(type, 1, 4, f);
    if (len) fwrite(data, 1, len, f);
    c = crc_update(0xffffffffu, (const unsigned char *)type, 4);
    c = crc_update(c, data, len) ^ 0xffffffffu;
    put32(b, c);
    fwrite(b, 1, 4, f);
}

/* Writes `rgba` (rows top to bottom) to `path`, via a temporary file renamed into place. */
static void write_png(const char *path, const unsigned char *rgba, uint32_t w, uint32_t h) {
    size_t row = (size_t)w * 4 + 1, raw_len = row * h, blocks = raw_len / 65535 + 1;
    size_t z_len = 2 + raw_len + 5 * blocks + 4, at = 0, done = 0, y;
    unsigned char *raw = xmalloc(raw_len), *z = xmalloc(z_len), ihdr[13];
    uint32_t s1 = 1, s2 = 0;
    char tmp[4200];
    FILE *f;
    static const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    for (y = 0; y < h; y++) {
        raw[y * row] = 0; /* filter: none */
        memcpy(raw + y * row + 1, rgba + y * (size_t)w * 4, (size_t)w * 4);
    }
    z[at++] = 0x78;
    z[at++] = 0x01;
    do {
        size_t n = raw_len - done > 65535 ? 65535 : raw_len - done;
        z[at++] = (unsigned char)(done + n == raw_len); /* BFINAL, BTYPE 00: stored */
        z[at++] = (unsigned char)(n & 0xff);
        z[at++] = (unsigned char)(n >> 8);
        z[at++] = (unsigned char)(~n & 0xff);
        z[at++] = (unsigned char)((~n >> 8) & 0xff);
        memcpy(z + at, raw + done, n);
        at += n;
        done += n;
    } while (done < raw_len);
    for (y = 0; y < raw_len; y++) {
        s1 = (s1 + raw[y]) % 65521;
        s2 = (s2 + s1) % 65521;
    }
    put32(z + at, (s2 << 16) | s1);
    at += 4;
    put32(ihdr, w);
    put32(ihdr + 4, h);
    ihdr[8] = 8;  /* bit depth */
    ihdr[9] = 6;  /* colour type: RGBA */
    ihdr[10] = 0; /* deflate */
    ihdr[11] = 0; /* adaptive filtering */
    ihdr[12] = 0; /* no interlace */
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    f = fopen(tmp, "wb");
    if (!f) die("cannot create a PNG file (does the output folder exist?)");
    fwrite(sig, 1, 8, f);
    chunk(f, "IHDR", ihdr, 13);
    chunk(f, "IDAT", z, (uint32_t)at);
    chunk(f, "IEND", NULL, 0);
    if (fclose(f) != 0 || rename(tmp, path) != 0) die("cannot write a PNG file");
    free(raw);
    free(z);
}

/* ---- shaders ---- */

static const char *VS =
    "#version 300 es\n"
    "precision highp float;\n"
    "precision highp int;\n"
    "layout(location = 0) in vec3 a_position;\n"
    "layout(location = 1) in vec3 a_normal;\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "layout(location = 3) in uint a_material;\n"
    "layout(location = 4) in uint a_node;\n"
    "layout(location = 5) in vec2 a_uv1;\n"
    "uniform mat4 u_proj;\n"
    "uniform highp sampler2D u_nodes;\n" /* 4 texels (columns) per node: view x world */
    "flat out uint v_material;\n"
    "out vec2 v_uv;\n"
    "out vec2 v_uv1;\n"
    "out vec3 v_normal;\n"
    "invariant gl_Position;\n"
    "void main() {\n"
    "  int n = int(a_node);\n"
    "  mat4 m = mat4(texelFetch(u_nodes, ivec2(0, n), 0), texelFetch(u_nodes, ivec2(1, n), 0),\n"
    "                texelFetch(u_nodes, ivec2(2, n), 0), texelFetch(u_nodes, ivec2(3, n), 0));\n"
    "  gl_Position = u_proj * (m * vec4(a_position, 1.0));\n"
    "  v_material = a_material;\n"
    "  v_uv = a_uv;\n"
    "  v_uv1 = a_uv1;\n"
    "  v_normal = (m * vec4(a_normal, 0.0)).xyz;\n"
    "}\n";

static const char *FS =
    "#version 300 es\n"
    "precision highp float;\n"
    "precision highp int;\n"
    "precision highp sampler2DArray;\n"
    "flat in uint v_material;\n"
    "in vec2 v_uv;\n"
    "in vec2 v_uv1;\n"
    "in vec3 v_normal;\n"
    /* 6 texels per material: base colour; emissive + transmission; alpha mode, cutoff,
     * double sided, texture layer (-1: none); uv scale into the layer; the base-colour
     * texture's KHR_texture_transform rows (u', v') with its texture coordinate set in the
     * first row's w. */
    "uniform highp sampler2D u_materials;\n"
    "uniform sampler2DArray u_textures;\n"
    "uniform vec4 u_light;\n"
    "uniform float u_glass_opacity;\n"
    "uniform int u_premultiplied;\n"
    "out vec4 o_colour;\n"
    "void main() {\n"
    "  int mi = int(v_material);\n"
    "  vec4 base = texelFetch(u_materials, ivec2(0, mi), 0);\n"
    "  vec4 emissive = texelFetch(u_materials, ivec2(1, mi), 0);\n"
    "  vec4 params = texelFetch(u_materials, ivec2(2, mi), 0);\n"
    "  vec4 uv_scale = texelFetch(u_materials, ivec2(3, mi), 0);\n"
    "  vec4 tu = texelFetch(u_materials, ivec2(4, mi), 0);\n"
    "  vec4 tv = texelFetch(u_materials, ivec2(5, mi), 0);\n"
    "  vec3 st = vec3(tu.w > 0.5 ? v_uv1 : v_uv, 1.0);\n"
    "  vec2 uv = vec2(dot(tu.xyz, st), dot(tv.xyz, st));\n"
    "  if (params.z < 0.5 && !gl_FrontFacing) discard;\n"
    "  vec4 c = base;\n"
    "  if (params.w >= 0.0) c *= textureLod(u_textures, vec3(fract(uv) * uv_scale.xy, params.w), 0.0);\n"
    "  int mode = int(params.x);\n"
    "  if (emissive.a > 0.0) c.a = u_glass_opacity;\n"
    "  else if (mode == 0) c.a = 1.0;\n"
    "  else if (mode == 1) { if (c.a < params.y) discard; c.a = 1.0; }\n"
    "  vec3 n = normalize(v_normal + vec3(0.0, 0.0, 1e-12));\n"
    "  if (!gl_FrontFacing) n = -n;\n"
    "  float diffuse = max(dot(n, normalize(u_light.xyz)), 0.0);\n"
    "  vec3 lit = c.rgb * (u_light.w + (1.0 - u_light.w) * diffuse) + emissive.rgb;\n"
    "  float a = clamp(c.a, 0.0, 1.0);\n"
    "  o_colour = u_premultiplied != 0 ? vec4(lit * a, a) : vec4(lit, a);\n"
    "}\n";

static GLuint compile(GLenum type, const char *src) {
    GLuint s = glCreateShader(type);
    GLint ok = 0;
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "host: error: shader: %s\n", log);
        exit(1);
    }
    return s;
}

/* ---- EGL ---- */


static void open_gles(void) {
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display;
    EGLDisplay dpy = EGL_NO_DISPLAY;
    EGLConfig config;
    EGLint n = 0, major, minor;
    EGLContext ctx;
    EGLSurface surface = EGL_NO_SURFACE;
    static const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT,
                                            EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
    static const EGLint ctx_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION,
                                         0, EGL_NONE};
    static const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    /* Mesa's surfaceless platform: no display server needed. */
    *(void **)(&get_platform_display) = (void *)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (get_platform_display)
        dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (dpy == EGL_NO_DISPLAY) dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor))
        die("no EGL display (install libegl-mesa0)");
    if (!eglBindAPI(EGL_OPENGL_ES_API)) die("EGL cannot bind OpenGL ES");
    if (!eglChooseConfig(dpy, config_attribs, &config, 1, &n) || n < 1)
        die("no EGL config for OpenGL ES 3 pbuffers");
    ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, ctx_attribs);
    if (ctx == EGL_NO_CONTEXT) die("cannot create an OpenGL ES 3.0 context");
    surface = eglCreatePbufferSurface(dpy, config, pbuffer_attribs);
    if (!eglMakeCurrent(dpy, surface, surface, ctx)) die("cannot make the context current");
    fprintf(stderr, "host: EGL %d.%d, %s, %s\n", (int)major, (int)minor,
            (const char *)glGetString(GL_RENDERER), (const char *)glGetString(GL_VERSION));
}

/* A sampled RGBA32F data texture, `height` rows of `width` texels. */
static GLuint data_texture(GLsizei width, GLsizei height, const float *texels) {
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, texels);
    return t;
}

/* ---- --shading pbr: the player's exported shaders (trisort export-shaders) ---- */

/* The whole of file `dir`/`name`, NUL-terminated. */
static char *read_text(const char *dir, const char *name) {
    char path[4096];
    FILE *f;
    long n;
    char *text;
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) die("shader path too long");
    f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "host: error: cannot open %s (write it with trisort export-shaders)\n", path);
        exit(1);
    }
    if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0)
        die("cannot read a shader file");
    text = xmalloc((size_t)n + 1);
    if (fread(text, 1, (size_t)n, f) != (size_t)n) die("cannot read a shader file");
    text[n] = 0;
    fclose(f);
    return text;
}

/* Binds the program's uniform blocks and samplers as bindings.txt names them for the stage
 * files `vert` and `frag`: uniform block of WGSL binding B at binding point B, the sampler of
 * texture binding B at texture unit B. */
static void bind_exported_names(GLuint prog, const char *dir, const char *vert, const char *frag) {
    char *text = read_text(dir, "bindings.txt"), *line = text, *next;
    for (; line && *line; line = next) {
        char file[256], kind[32], name[256];
        unsigned group, binding;
        next = strchr(line, '\n');
        if (next) *next++ = 0;
        if (line[0] == '#' ||
            sscanf(line, "%255s %31s %u %u %255s", file, kind, &group, &binding, name) != 5)
            continue;
        if (strcmp(file, vert) != 0 && strcmp(file, frag) != 0) continue;
        if (!strcmp(kind, "uniform")) {
            GLuint index = glGetUniformBlockIndex(prog, name);
            if (index != GL_INVALID_INDEX) glUniformBlockBinding(prog, index, binding);
        } else if (!strcmp(kind, "texture")) {
            GLint location = glGetUniformLocation(prog, name);
            if (location >= 0) glUniform1i(location, (GLint)binding);
        }
    }
    free(text);
    check_gl("exported bindings");
}

/* A uniform buffer of `size` bytes bound at binding point `point`. */
static GLuint uniform_buffer(GLuint point, size_t size, const void *data) {
    GLuint b;
    glGenBuffers(1, &b);
    glBindBuffer(GL_UNIFORM_BUFFER, b);
    glBufferData(GL_UNIFORM_BUFFER, (GLsizeiptr)size, data, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, point, b);
    return b;
}

/* Trilinear filtering on the texture bound to `target`, wrapping s as `wrap_s`. */
static void trilinear(GLenum target, GLint wrap_s) {
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, wrap_s);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

/* Material texture array `array` as the player uploads it, on texture unit `unit`. */
static void upload_texture_array(TrisortBaked *h, uint32_t array, GLuint unit, uint32_t max_size) {
    TrisortGpuTexture t;
    GLuint tex;
    uint32_t layer, level;
    size_t n = 0;
    unsigned char *texels;
    check(trisort_gpu_texture_array(h, array, max_size, &t), "trisort_gpu_texture_array");
    glActiveTexture(GL_TEXTURE0 + unit);
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, (GLsizei)t.levels,
                   array == TRISORT_TEXTURE_ARRAY_SRGB ? GL_SRGB8_ALPHA8 : GL_RGBA8,
                   (GLsizei)t.width, (GLsizei)t.height, (GLsizei)t.layers);
    texels = xmalloc((size_t)t.width * t.height * 4);
    for (layer = 0; layer < t.layers; layer++) {
        for (level = 0; level < t.levels; level++) {
            uint32_t lw = t.width >> level ? t.width >> level : 1;
            uint32_t lh = t.height >> level ? t.height >> level : 1;
            check(trisort_gpu_texture_array_level(h, array, layer, level, max_size, texels,
                                                  (size_t)t.width * t.height * 4, &n),
                  "trisort_gpu_texture_array_level");
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, (GLint)level, 0, 0, (GLint)layer, (GLsizei)lw,
                            (GLsizei)lh, 1, GL_RGBA, GL_UNSIGNED_BYTE, texels);
        }
    }
    free(texels);
    trilinear(GL_TEXTURE_2D_ARRAY, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, (GLint)t.levels - 1);
}

/* The prefiltered environment as the player uploads it, on texture unit `unit`. */
static void upload_environment(TrisortBaked *h, GLuint unit, uint32_t max_size) {
    TrisortGpuTexture t;
    GLuint tex;
    uint32_t level;
    size_t n = 0;
    uint16_t *texels;
    check(trisort_gpu_environment(h, max_size, &t), "trisort_gpu_environment");
    glActiveTexture(GL_TEXTURE0 + unit);
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, (GLsizei)t.levels, GL_RGBA16F, (GLsizei)t.width,
                   (GLsizei)t.height);
    texels = xmalloc((size_t)t.width * t.height * 4 * sizeof *texels);
    for (level = 0; level < t.levels; level++) {
        uint32_t lw = t.width >> level ? t.width >> level : 1;
        uint32_t lh = t.height >> level ? t.height >> level : 1;
        check(trisort_gpu_environment_level(h, level, max_size, texels,
                                            (size_t)t.width * t.height * 4, &n),
              "trisort_gpu_environment_level");
        glTexSubImage2D(GL_TEXTURE_2D, (GLint)level, 0, 0, (GLsizei)lw, (GLsizei)lh, GL_RGBA,
                        GL_HALF_FLOAT, texels);
    }
    free(texels);
    /* The environment wraps around in longitude (s) and stops at the poles (t). */
    trilinear(GL_TEXTURE_2D, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, (GLint)t.levels - 1);
}

/* A data texture (RGBA32F, TRISORT_GPU_DATA_WIDTH texels a row) of `floats` floats on unit
 * `unit`. */
static void upload_data_texture(GLuint unit, const float *floats, size_t n) {
    glActiveTexture(GL_TEXTURE0 + unit);
    data_texture(TRISORT_GPU_DATA_WIDTH, (GLsizei)(n / 4 / TRISORT_GPU_DATA_WIDTH), floats);
}

/* What --shading pbr keeps per frame: the Frame and node-base uniform buffers. */
typedef struct {
    GLuint frame_ubo, node_base_ubo;
    uint32_t nodes_per_frame;
} Pbr;

/* Builds the program from the exported GLSL in `dir` (the straight- or premultiplied-alpha
 * fragment stage for `mode`) and uploads everything it reads, each WGSL binding B at texture
 * unit B or uniform binding point B. Leaves the program in use. */
static Pbr setup_pbr(TrisortBaked *h, const TrisortInfo *info, const char *dir, TrisortMode mode) {
    const char *frag = mode == TRISORT_MODE_SATURATE ? "pbr_premultiplied.frag" : "pbr_straight.frag";
    char *vs = read_text(dir, "player.vert"), *fs = read_text(dir, frag);
    GLuint prog = glCreateProgram();
    GLint ok = 0, max_size = 0;
    unsigned char uniform[TRISORT_GPU_LIGHTING_UNIFORM_SIZE];
    uint32_t zero[4] = {0, 0, 0, 0};
    float *floats;
    size_t n = 0;
    Pbr p;
    glAttachShader(prog, compile(GL_VERTEX_SHADER, vs));
    glAttachShader(prog, compile(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(prog);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetProgramInfoLog(prog, sizeof log, NULL, log);
        fprintf(stderr, "host: error: the exported shaders do not link: %s\n", log);
        exit(1);
    }
    free(vs);
    free(fs);
    glUseProgram(prog);
    bind_exported_names(prog, dir, "player.vert", frag);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);

    p.frame_ubo = uniform_buffer(0, TRISORT_GPU_FRAME_UNIFORM_SIZE, NULL);
    p.node_base_ubo = uniform_buffer(1, sizeof zero, zero);
    p.nodes_per_frame = info->node_count ? info->node_count : 1;
    check(trisort_gpu_lighting_uniform(h, TRISORT_SHADING_PBR, TRISORT_TONE_MAP_NEUTRAL,
                                       (uint32_t)max_size, uniform, sizeof uniform, &n),
          "trisort_gpu_lighting_uniform");
    uniform_buffer(7, n, uniform);

    check(trisort_gpu_material_texels(h, (uint32_t)max_size, NULL, 0, &n), "trisort_gpu_material_texels");
    floats = xmalloc(n * sizeof *floats);
    check(trisort_gpu_material_texels(h, (uint32_t)max_size, floats, n, &n), "trisort_gpu_material_texels");
    upload_data_texture(2, floats, n);
    free(floats);
    check(trisort_gpu_node_texels(h, NULL, 0, &n), "trisort_gpu_node_texels");
    floats = xmalloc(n * sizeof *floats);
    check(trisort_gpu_node_texels(h, floats, n, &n), "trisort_gpu_node_texels");
    upload_data_texture(5, floats, n);
    free(floats);
    upload_texture_array(h, TRISORT_TEXTURE_ARRAY_SRGB, 3, (uint32_t)max_size);
    upload_texture_array(h, TRISORT_TEXTURE_ARRAY_LINEAR, 6, (uint32_t)max_size);
    upload_environment(h, 8, (uint32_t)max_size);
    glActiveTexture(GL_TEXTURE0);
    check_gl("pbr set-up");
    return p;
}

/* Frame `f`'s uniforms for --shading pbr: the Frame uniform at the recorded size and the
 * frame's first node in the node texels. */
static void pbr_frame(TrisortBaked *h, const Pbr *p, uint32_t f) {
    unsigned char frame[TRISORT_GPU_FRAME_UNIFORM_SIZE];
    uint32_t base[4] = {0, 0, 0, 0};
    size_t n = 0;
    check(trisort_gpu_frame_uniform(h, f, 0, 0, frame, sizeof frame, &n), "trisort_gpu_frame_uniform");
    glBindBuffer(GL_UNIFORM_BUFFER, p->frame_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, (GLsizeiptr)n, frame);
    base[0] = f * p->nodes_per_frame;
    glBindBuffer(GL_UNIFORM_BUFFER, p->node_base_ubo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof base, base);
}

static float linear_to_srgb(float c) {
    c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

int main(int argc, char **argv) {
    TrisortBaked *h = NULL;
    TrisortInfo info;
    TrisortMode mode;
    TrisortVertex *vertices;
    TrisortMaterial *materials;
    TrisortRange *ranges;
    float *node_texels, *material_texels, *pixels, proj[16];
    unsigned char *rgba;
    size_t nv, nidx, nm, nn = 0, nr, k;
    uint32_t f, tw = 1, th = 1, t, w, hgt, samples, x, y, clip, first = 0, count;
    GLuint prog = 0, vao, vbo, ibo, nodes_tex = 0, materials_tex, array_tex, fbo[2], rb[3];
    int bytes_per_index, back_to_front, pbr = 0, a;
    const char *mode_name = NULL, *shaders = NULL, *clip_name = NULL;
    char path[4096];
    Pbr pbr_state = {0, 0, 1};

    for (a = 3; a < argc; a++) {
        if (!strcmp(argv[a], "--shading") && a + 1 < argc) {
            a++;
            if (!strcmp(argv[a], "pbr")) pbr = 1;
            else if (strcmp(argv[a], "basic") != 0) die("--shading must be basic or pbr");
        } else if (!strcmp(argv[a], "--shaders") && a + 1 < argc) {
            shaders = argv[++a];
        } else if (!strcmp(argv[a], "--clip") && a + 1 < argc) {
            clip_name = argv[++a];
        } else if (!mode_name && argv[a][0] != '-') {
            mode_name = argv[a];
        } else {
            argc = 0; /* usage */
        }
    }
    if (argc < 3) {
        fprintf(stderr, "usage: host BAKED OUT_DIR [blend|depth|saturate] [--shading basic|pbr] "
                        "[--shaders DIR] [--clip NAME]\n");
        return 2;
    }
    if (pbr && !shaders) die("--shading pbr needs --shaders DIR (trisort export-shaders --lang glsl-es-300 -o DIR)");
    if (trisort_abi_version() < TRISORT_ABI_VERSION) die("libtrisort_capi is older than trisort.h (ABI version below the header's)");
    check(trisort_open_path(argv[1], &h), "trisort_open_path");
    check(trisort_info(h, &info), "trisort_info");
    count = info.frame_count;
    if (clip_name) {
        /* A clip is a run of the file's frames; an unknown name fails listing the clips. */
        check(trisort_clip_find(h, clip_name, &clip), "trisort_clip_find");
        check(trisort_clip_frames(h, clip, &first, &count), "trisort_clip_frames");
    }
    mode = info.recommended_mode;
    if (mode_name) {
        if (!strcmp(mode_name, "blend")) mode = TRISORT_MODE_BLEND;
        else if (!strcmp(mode_name, "depth")) mode = TRISORT_MODE_DEPTH;
        else if (!strcmp(mode_name, "saturate")) mode = TRISORT_MODE_SATURATE;
        else die("mode must be blend, depth or saturate");
    }
    back_to_front = mode == TRISORT_MODE_BLEND;
    w = info.width;
    hgt = info.height;
    samples = info.samples;
    crc_init();
    open_gles();

    /* Vertex streams: interleaved, 64 bytes a vertex (sizeof(TrisortVertex)). */
    check(trisort_vertices(h, NULL, 0, &nv), "trisort_vertices");
    vertices = xmalloc(nv * sizeof *vertices);
    check(trisort_vertices(h, vertices, nv, &nv), "trisort_vertices");
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * sizeof *vertices), vertices, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)12);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)24);
    glEnableVertexAttribArray(3);
    glVertexAttribIPointer(3, 1, GL_UNSIGNED_INT, sizeof(TrisortVertex), (void *)32);
    glEnableVertexAttribArray(4);
    glVertexAttribIPointer(4, 1, GL_UNSIGNED_INT, sizeof(TrisortVertex), (void *)36);
    if (pbr) {
        /* The exported vertex stage reads the tangent (location 5) and uv1 (location 6). */
        glEnableVertexAttribArray(5);
        glVertexAttribPointer(5, 4, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)40);
        glEnableVertexAttribArray(6);
        glVertexAttribPointer(6, 2, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)56);
    } else {
        /* The tangent at byte 40 is not used: the basic shaders shade with normals alone. */
        glEnableVertexAttribArray(5);
        glVertexAttribPointer(5, 2, GL_FLOAT, GL_FALSE, sizeof(TrisortVertex), (void *)56);
    }
    free(vertices);

    /* The sorted index buffer, reversed for back-to-front blending; u16 where it fits. */
    glGenBuffers(1, &ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    if (info.fits_u16) {
        uint16_t *idx;
        check(trisort_indices_u16(h, back_to_front, NULL, 0, &nidx), "trisort_indices_u16");
        idx = xmalloc(nidx * 2);
        check(trisort_indices_u16(h, back_to_front, idx, nidx, &nidx), "trisort_indices_u16");
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(nidx * 2), idx, GL_STATIC_DRAW);
        free(idx);
        bytes_per_index = 2;
    } else {
        uint32_t *idx;
        check(trisort_indices_u32(h, back_to_front, NULL, 0, &nidx), "trisort_indices_u32");
        idx = xmalloc(nidx * 4);
        check(trisort_indices_u32(h, back_to_front, idx, nidx, &nidx), "trisort_indices_u32");
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(nidx * 4), idx, GL_STATIC_DRAW);
        free(idx);
        bytes_per_index = 4;
    }

    if (pbr) {
        pbr_state = setup_pbr(h, &info, shaders, mode);
        node_texels = NULL;
    } else {
        /* Base-colour textures in one sRGB array, each layer as large as the largest texture,
         * smaller ones in the top-left corner (as trisort's player does). */
        for (t = 0; t < info.texture_count; t++) {
            uint32_t tx, ty;
            check(trisort_texture(h, t, &tx, &ty, NULL, 0, &k), "trisort_texture");
            if (tx > tw) tw = tx;
            if (ty > th) th = ty;
        }
        glGenTextures(1, &array_tex);
        glBindTexture(GL_TEXTURE_2D_ARRAY, array_tex);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_SRGB8_ALPHA8, (GLsizei)tw, (GLsizei)th,
                     (GLsizei)(info.texture_count ? info.texture_count : 1), 0, GL_RGBA,
                     GL_UNSIGNED_BYTE, NULL);
        for (t = 0; t < info.texture_count; t++) {
            uint32_t tx, ty;
            unsigned char *texels;
            check(trisort_texture(h, t, &tx, &ty, NULL, 0, &k), "trisort_texture");
            texels = xmalloc(k);
            check(trisort_texture(h, t, &tx, &ty, texels, k, &k), "trisort_texture");
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, (GLint)t, (GLsizei)tx, (GLsizei)ty, 1,
                            GL_RGBA, GL_UNSIGNED_BYTE, texels);
            free(texels);
        }
        check_gl("textures");

        /* Materials: 6 texels each. */
        check(trisort_materials(h, NULL, 0, &nm), "trisort_materials");
        materials = xmalloc(nm * sizeof *materials);
        check(trisort_materials(h, materials, nm, &nm), "trisort_materials");
        material_texels = xmalloc(nm * 24 * sizeof(float));
        for (k = 0; k < nm; k++) {
            const TrisortMaterial *m = &materials[k];
            float *p = material_texels + 24 * k;
            float sx = 1.0f, sy = 1.0f;
            if (m->base_color_texture >= 0) {
                uint32_t tx, ty;
                size_t bytes;
                check(trisort_texture(h, (uint32_t)m->base_color_texture, &tx, &ty, NULL, 0, &bytes),
                      "trisort_texture");
                sx = (float)tx / (float)tw;
                sy = (float)ty / (float)th;
            }
            memcpy(p, m->base_color, 4 * sizeof(float));
            memcpy(p + 4, m->emissive, 3 * sizeof(float));
            p[7] = m->transmission;
            p[8] = (float)m->alpha_mode;
            p[9] = m->alpha_cutoff;
            p[10] = m->double_sided ? 1.0f : 0.0f;
            p[11] = (float)m->base_color_texture;
            p[12] = sx;
            p[13] = sy;
            p[14] = 0.0f;
            p[15] = 0.0f;
            memcpy(p + 16, m->base_color_slot.transform, 3 * sizeof(float));
            p[19] = (float)m->base_color_slot.tex_coord;
            memcpy(p + 20, m->base_color_slot.transform + 3, 3 * sizeof(float));
            p[23] = 0.0f;
        }
        materials_tex = data_texture(6, (GLsizei)nm, material_texels);
        free(material_texels);
        free(materials);

        check(trisort_frame_node_matrices(h, 0, true, NULL, 0, &nn), "trisort_frame_node_matrices");
        node_texels = xmalloc(nn * sizeof(float));
        check(trisort_frame_node_matrices(h, 0, true, node_texels, nn, &nn), "trisort_frame_node_matrices");
        nodes_tex = data_texture(4, (GLsizei)(nn / 16), node_texels);

        prog = glCreateProgram();
        glAttachShader(prog, compile(GL_VERTEX_SHADER, VS));
        glAttachShader(prog, compile(GL_FRAGMENT_SHADER, FS));
        glLinkProgram(prog);
        {
            GLint ok = 0;
            glGetProgramiv(prog, GL_LINK_STATUS, &ok);
            if (!ok) die("shader program does not link");
        }
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_nodes"), 0);
        glUniform1i(glGetUniformLocation(prog, "u_materials"), 1);
        glUniform1i(glGetUniformLocation(prog, "u_textures"), 2);
        glUniform4fv(glGetUniformLocation(prog, "u_light"), 1, LIGHT);
        glUniform1f(glGetUniformLocation(prog, "u_glass_opacity"), info.glass_opacity);
        glUniform1i(glGetUniformLocation(prog, "u_premultiplied"), mode == TRISORT_MODE_SATURATE);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, nodes_tex);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, materials_tex);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D_ARRAY, array_tex);
        glActiveTexture(GL_TEXTURE0);
    }

    /* Target: multisampled linear RGBA16F (and depth in depth mode), resolved into a
     * single-sample RGBA16F that is read back as floats. */
    glGenFramebuffers(2, fbo);
    glGenRenderbuffers(3, rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? (GLsizei)samples : 0,
                                     GL_RGBA16F, (GLsizei)w, (GLsizei)hgt);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples > 1 ? (GLsizei)samples : 0,
                                     GL_DEPTH_COMPONENT32F, (GLsizei)w, (GLsizei)hgt);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[2]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA16F, (GLsizei)w, (GLsizei)hgt);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        die("the RGBA16F multisampled target is incomplete (no EXT_color_buffer_float?)");
    glBindFramebuffer(GL_FRAMEBUFFER, fbo[1]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[2]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        die("the RGBA16F resolve target is incomplete");
    check_gl("targets");

    glViewport(0, 0, (GLsizei)w, (GLsizei)hgt);
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CW);
    glEnable(GL_BLEND);
    if (mode == TRISORT_MODE_SATURATE) {
        glBlendFunc(GL_ONE_MINUS_DST_ALPHA, GL_ONE); /* premultiplied, under */
    } else {
        glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    }
    if (mode == TRISORT_MODE_DEPTH) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    pixels = xmalloc((size_t)w * hgt * 4 * sizeof(float));
    rgba = xmalloc((size_t)w * hgt * 4);
    ranges = NULL;
    for (f = first; f < first + count; f++) {
        check(trisort_frame_projection(h, f, (double)w / (double)hgt,
                                       TRISORT_DEPTH_RANGE_MINUS_ONE_TO_ONE, proj),
              "trisort_frame_projection");
        /* Draw upside down (clip y negated, so front faces turn clockwise): GL's row 0 is then
         * the image's top row, and MSAA sample positions, which GL gives from a pixel's lower
         * corner, fall where Vulkan's (from its upper corner) do. */
        for (k = 0; k < 4; k++) proj[4 * k + 1] = -proj[4 * k + 1];
        if (pbr) {
            /* The exported vertex stage negates y itself (and maps depth to GL's), from the
             * player's own Frame uniform. */
            pbr_frame(h, &pbr_state, f);
        } else {
            glUniformMatrix4fv(glGetUniformLocation(prog, "u_proj"), 1, GL_FALSE, proj);
            check(trisort_frame_node_matrices(h, f, true, node_texels, nn, &nn),
                  "trisort_frame_node_matrices");
            glBindTexture(GL_TEXTURE_2D, nodes_tex);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, (GLsizei)(nn / 16), GL_RGBA, GL_FLOAT,
                            node_texels);
        }
        glBindFramebuffer(GL_FRAMEBUFFER, fbo[0]);
        if (mode == TRISORT_MODE_SATURATE) glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
        else glClearColor(BACKGROUND[0], BACKGROUND[1], BACKGROUND[2], 1.0f);
        glClearDepthf(1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        check(trisort_frame_ranges(h, f, back_to_front, NULL, 0, &nr), "trisort_frame_ranges");
        ranges = realloc(ranges, (nr ? nr : 1) * sizeof *ranges);
        if (!ranges) die("out of memory");
        check(trisort_frame_ranges(h, f, back_to_front, ranges, nr, &nr), "trisort_frame_ranges");
        for (k = 0; k < nr; k++) {
            glDrawElements(GL_TRIANGLES, (GLsizei)ranges[k].count,
                           bytes_per_index == 2 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT,
                           (const void *)((uintptr_t)ranges[k].first * (uintptr_t)bytes_per_index));
        }
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo[0]);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo[1]);
        glBlitFramebuffer(0, 0, (GLint)w, (GLint)hgt, 0, 0, (GLint)w, (GLint)hgt,
                          GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo[1]);
        glReadPixels(0, 0, (GLsizei)w, (GLsizei)hgt, GL_RGBA, GL_FLOAT, pixels);
        check_gl("frame");
        /* Quantize once to 8-bit sRGB (rows already top to bottom: drawn upside down). */
        for (y = 0; y < hgt; y++) {
            for (x = 0; x < w; x++) {
                const float *px = pixels + ((size_t)y * w + x) * 4;
                unsigned char *o = rgba + ((size_t)y * w + x) * 4;
                float a = px[3] < 0.0f ? 0.0f : (px[3] > 1.0f ? 1.0f : px[3]);
                int c;
                for (c = 0; c < 3; c++) {
                    float v = px[c];
                    if (mode == TRISORT_MODE_SATURATE) v += (1.0f - a) * BACKGROUND[c];
                    o[c] = (unsigned char)floorf(linear_to_srgb(v) * 255.0f + 0.5f);
                }
                o[3] = 255;
            }
        }
        if (snprintf(path, sizeof path, "%s/frame-%05u.png", argv[2], (unsigned)f) >= (int)sizeof path)
            die("output folder path too long");
        write_png(path, rgba, w, hgt);
    }
    printf("host: drew %u frames (%s, %s shading) at %ux%u, %ux MSAA into %s\n",
           (unsigned)count,
           mode == TRISORT_MODE_BLEND ? "blend" : mode == TRISORT_MODE_DEPTH ? "depth" : "saturate",
           pbr ? "pbr" : "basic", (unsigned)w, (unsigned)hgt, (unsigned)samples, argv[2]);
    free(ranges);
    free(pixels);
    free(rgba);
    free(node_texels);
    trisort_close(h);
    return 0;
}
