/* A C reader of baked files: opens one through trisort.h and prints its figures and a digest
 * of everything a host copies out (indices in both orders and widths, every frame's ranges
 * and indirect draws, vertices, materials, every frame's view and world node matrices,
 * textures). No graphics API: it runs wherever the library does, so CI runs it natively and
 * under qemu-aarch64 and compares the two outputs (scripts/test-capi-package.sh).
 *
 *   reader FILE.baked      prints `key value` lines; exit status 1 with the library's message
 *                          on a file it refuses.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trisort.h"

static uint64_t digest = 1469598103934665603ull; /* FNV-1a, 64 bits */

static void mix(const void *data, size_t bytes) {
  const unsigned char *p = data;
  for (size_t i = 0; i < bytes; i++) {
    digest = (digest ^ p[i]) * 1099511628211ull;
  }
}

static int fail(const char *what) {
  char message[1024];
  trisort_last_error(message, sizeof message);
  fprintf(stderr, "reader: %s: %s\n", what, message);
  return 1;
}

/* The copy convention: ask for the length, allocate, copy. */
#define COPY(call_with, type, out_ptr, out_len)                                   \
  do {                                                                            \
    size_t n_ = 0;                                                                \
    type *o_ = NULL;                                                              \
    if (call_with(NULL, 0, &n_) != TRISORT_STATUS_OK) return fail(#call_with);    \
    o_ = malloc(n_ ? n_ * sizeof(type) : 1);                                      \
    if (!o_) return fail("out of memory");                                        \
    if (call_with(o_, n_, &n_) != TRISORT_STATUS_OK) return fail(#call_with);     \
    out_ptr = o_;                                                                 \
    out_len = n_;                                                                 \
  } while (0)

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: reader FILE.baked\n");
    return 2;
  }
  if (trisort_abi_version() < TRISORT_ABI_VERSION) {
    fprintf(stderr, "reader: library ABI %u is older than the header's %u\n",
            trisort_abi_version(), (unsigned)TRISORT_ABI_VERSION);
    return 1;
  }
  TrisortBaked *h = NULL;
  if (trisort_open_path(argv[1], &h) != TRISORT_STATUS_OK) return fail("open");
  TrisortInfo info;
  if (trisort_info(h, &info) != TRISORT_STATUS_OK) return fail("info");
  printf("format_version %u\n", trisort_format_version());
  printf("frames %u\nsize %ux%u\nsamples %u\n", info.frame_count, info.width, info.height,
         info.samples);
  printf("vertices %u\ntriangles %u\nindex_triangles %u\ndraws %u\n", info.vertex_count,
         info.triangle_count, info.index_triangle_count, info.draw_count);
  printf("materials %u\ntextures %u\nnodes %u\n", info.material_count, info.texture_count,
         info.node_count);

  for (int back_to_front = 0; back_to_front < 2; back_to_front++) {
    uint32_t *idx;
    size_t n;
#define INDICES32(o, c, l) trisort_indices_u32(h, back_to_front, o, c, l)
    COPY(INDICES32, uint32_t, idx, n);
    mix(idx, n * sizeof *idx);
    free(idx);
    if (info.fits_u16) {
      uint16_t *idx16;
#define INDICES16(o, c, l) trisort_indices_u16(h, back_to_front, o, c, l)
      COPY(INDICES16, uint16_t, idx16, n);
      mix(idx16, n * sizeof *idx16);
      free(idx16);
    }
    for (uint32_t f = 0; f < info.frame_count; f++) {
      TrisortRange *ranges;
      TrisortDrawIndexedIndirectArgs *draws;
#define RANGES(o, c, l) trisort_frame_ranges(h, f, back_to_front, o, c, l)
#define DRAWS(o, c, l) trisort_frame_draws(h, f, back_to_front, o, c, l)
      COPY(RANGES, TrisortRange, ranges, n);
      mix(ranges, n * sizeof *ranges);
      free(ranges);
      COPY(DRAWS, TrisortDrawIndexedIndirectArgs, draws, n);
      mix(draws, n * sizeof *draws);
      free(draws);
    }
  }
  printf("digest_order %016llx\n", (unsigned long long)digest);

  TrisortVertex *vertices;
  TrisortMaterial *materials;
  size_t n;
#define VERTICES(o, c, l) trisort_vertices(h, o, c, l)
#define MATERIALS(o, c, l) trisort_materials(h, o, c, l)
  COPY(VERTICES, TrisortVertex, vertices, n);
  mix(vertices, n * sizeof *vertices);
  free(vertices);
  printf("digest_vertices %016llx\n", (unsigned long long)digest);
  COPY(MATERIALS, TrisortMaterial, materials, n);
  /* Field by field: the struct's padding bytes are unspecified. */
  for (size_t m = 0; m < n; m++) {
    const TrisortMaterial *t = &materials[m];
    const TrisortTextureSlot *slots[] = {&t->base_color_slot, &t->metallic_roughness, &t->normal,
                                         &t->occlusion, &t->emissive_texture};
    float factors[] = {t->alpha_cutoff, t->transmission, t->metallic, t->roughness,
                       t->normal_scale, t->occlusion_strength, t->clearcoat,
                       t->clearcoat_roughness};
    uint32_t flags[] = {(uint32_t)t->alpha_mode, t->double_sided ? 1u : 0u};
    mix(t->base_color, sizeof t->base_color);
    mix(t->emissive, sizeof t->emissive);
    mix(factors, sizeof factors);
    mix(flags, sizeof flags);
    for (size_t k = 0; k < sizeof slots / sizeof *slots; k++) {
      mix(slots[k], sizeof *slots[k]);
    }
  }
  free(materials);
  for (uint32_t t = 0; t < info.texture_count; t++) {
    uint8_t *texels;
    uint32_t width, height;
#define TEXTURE(o, c, l) trisort_texture(h, t, &width, &height, o, c, l)
    COPY(TEXTURE, uint8_t, texels, n);
    mix(texels, n);
    free(texels);
  }
  printf("digest_content %016llx\n", (unsigned long long)digest);

  for (uint32_t f = 0; f < info.frame_count; f++) {
    float view[16];
    float *nodes;
    if (trisort_frame_view(h, f, view) != TRISORT_STATUS_OK) return fail("view");
    mix(view, sizeof view);
#define NODES(o, c, l) trisort_frame_node_matrices(h, f, false, o, c, l)
    COPY(NODES, float, nodes, n);
    mix(nodes, n * sizeof *nodes);
    free(nodes);
  }
  printf("digest_frames %016llx\n", (unsigned long long)digest);

  /* The clips (ABI 6): the camera paths the file bundles, each a run of its frames. */
  uint32_t clips = 0;
  if (trisort_clip_count(h, &clips) != TRISORT_STATUS_OK) return fail("clip_count");
  printf("clips %u\n", clips);
  for (uint32_t k = 0; k < clips; k++) {
    char name[80]; /* names are at most 64 bytes */
    size_t len = 0;
    uint32_t first = 0, count = 0, found = 0;
    double fps = 0.0;
    if (trisort_clip_name(h, k, name, sizeof name, &len) != TRISORT_STATUS_OK)
      return fail("clip_name");
    if (trisort_clip_frames(h, k, &first, &count) != TRISORT_STATUS_OK) return fail("clip_frames");
    TrisortStatus s = trisort_clip_fps(h, k, &fps);
    if (s != TRISORT_STATUS_OK && s != TRISORT_STATUS_ABSENT) return fail("clip_fps");
    if (trisort_clip_find(h, name, &found) != TRISORT_STATUS_OK || found != k)
      return fail("clip_find");
    printf("clip %s frames %u+%u fps %.17g\n", name, first, count, fps);
  }

  /* Refusals: a frame out of range, a depth range outside the enum, a clip out of range. */
  float p[16];
  if (trisort_frame_projection(h, info.frame_count, 1.0, TRISORT_DEPTH_RANGE_ZERO_TO_ONE, p) !=
      TRISORT_STATUS_OUT_OF_RANGE) {
    fprintf(stderr, "reader: a frame out of range was not refused\n");
    return 1;
  }
  if (trisort_frame_projection(h, 0, 1.0, 7u, p) != TRISORT_STATUS_OUT_OF_RANGE) {
    fprintf(stderr, "reader: depth range 7 was not refused\n");
    return 1;
  }
  uint32_t first = 0, count = 0;
  if (trisort_clip_frames(h, clips, &first, &count) != TRISORT_STATUS_OUT_OF_RANGE) {
    fprintf(stderr, "reader: a clip out of range was not refused\n");
    return 1;
  }
  printf("refusals ok\n");
  trisort_close(h);
  return 0;
}
