/* glTF as the web delivers it (docs/import-gltf.md, "Compressed geometry and
 * web textures"): every encoding of tests/importers_gltf/data/web-base.glb
 * (Draco, meshopt through gltf-transform and gltfpack, WebP lossless and lossy,
 * KHR_texture_basisu with a fallback) imports to the same scene within the
 * encoding's quantisation, and lying, truncated or corrupt compressed data is
 * refused in one line naming the file and the element. The files and the
 * script that makes them are in tests/importers_gltf/data (make_web.py). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/image.h"
#include "core/log.h"
#include "importers/import.h"
#include "importers/meshopt.h"
#include "renderer/render.h"
#include "scene/scene.h"
#include "tests/common/check.h"
#include "tests/common/render_run.h"

#include <meshoptimizer.h>

#define EXPECT(cond, ...) iris_check_record(!!(cond), __FILE__, __LINE__, __VA_ARGS__)

static iris_scene *load(const char *name, iris_status *status, char *msg, size_t msg_size) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", IRIS_GLTF_TEST_DATA, name);
  iris_import_options o = iris_import_options_default();
  o.keep_materials = true;
  iris_error e;
  iris_error_clear(&e);
  iris_scene *s = NULL;
  iris_status st = iris_import_gltf(path, &o, &s, &e);
  if (status) *status = st;
  if (msg) iris_error_format(&e, msg, msg_size);
  return s;
}

static iris_scene *load_ok(const char *name) {
  char msg[1400] = "";
  iris_status st;
  iris_scene *s = load(name, &st, msg, sizeof msg);
  EXPECT(st == IRIS_OK && s, "%s: %s", name, msg);
  return s;
}

/* One vertex in world space: position, unit normal, the uv the colour texture
 * reads (its KHR_texture_transform applied: gltfpack moves uv dequantisation there). */
typedef struct wvert {
  double p[3], n[3], uv[2];
} wvert;

static wvert *world_vertices(const iris_scene *s) {
  const iris_instance *in = &s->instances[0];
  const iris_mesh *m = &s->meshes[in->mesh];
  const iris_texture *t = NULL;
  if (m->material >= 0 && s->materials[m->material].color_texture >= 0)
    t = &s->textures[s->materials[m->material].color_texture];
  wvert *v = calloc(m->vertex_count, sizeof *v);
  for (uint32_t i = 0; i < m->vertex_count; i++) {
    const float *p = m->positions + 3 * i;
    double nl = 0;
    for (int r = 0; r < 3; r++) {
      v[i].p[r] = in->transform.m[r][3];
      for (int c = 0; c < 3; c++) {
        v[i].p[r] += in->transform.m[r][c] * p[c];
        /* uniform scales only (both encoders' node transforms): the linear part maps normals */
        if (m->normals) v[i].n[r] += in->transform.m[r][c] * m->normals[3 * i + c];
      }
      nl += v[i].n[r] * v[i].n[r];
    }
    for (int r = 0; r < 3 && nl > 0; r++) v[i].n[r] /= sqrt(nl);
    double u = m->uvs ? m->uvs[2 * i] : 0, w = m->uvs ? m->uvs[2 * i + 1] : 0;
    if (t && t->has_transform) {
      const double c = cos(t->rotation), sn = sin(t->rotation);
      v[i].uv[0] = t->offset[0] + c * t->scale[0] * u + sn * t->scale[1] * w;
      v[i].uv[1] = t->offset[1] - sn * t->scale[0] * u + c * t->scale[1] * w;
    } else {
      v[i].uv[0] = u, v[i].uv[1] = w;
    }
  }
  return v;
}

static int cmp_tri(const void *a, const void *b) {
  const uint32_t *x = a, *y = b;
  for (int k = 0; k < 3; k++)
    if (x[k] != y[k]) return x[k] < y[k] ? -1 : 1;
  return 0;
}

/* The same triangle with its smallest index first (orientation kept). */
static void canonical_tri(const uint32_t in[3], uint32_t out[3]) {
  int k = in[0] < in[1] ? (in[0] < in[2] ? 0 : 2) : (in[1] < in[2] ? 1 : 2);
  for (int j = 0; j < 3; j++) out[j] = in[(k + j) % 3];
}

/* Compares the encoded scene with the plain one: every encoded vertex is a
 * distinct plain vertex within the tolerances (position per axis, normal per
 * component, uv per component), and the triangles are the same triangles
 * with the same orientation (encoders reorder vertices and triangles, so the
 * comparison goes through that vertex map; indices must then match exactly). */
static size_t compare_geometry(const char *what, const iris_scene *base, const iris_scene *enc, double tol_p,
                               double tol_n, double tol_uv) {
  if (!base || !enc || enc->mesh_count != 1 || enc->instance_count != 1) {
    printf("%s: not one mesh and one instance\n", what);
    return SIZE_MAX;
  }
  const iris_mesh *mb = &base->meshes[0], *me = &enc->meshes[0];
  if (me->vertex_count != mb->vertex_count || me->triangle_count != mb->triangle_count || !me->normals != !mb->normals ||
      !me->uvs != !mb->uvs) {
    printf("%s: %u vertices %u triangles, plain %u %u, or other attributes\n", what, me->vertex_count,
           me->triangle_count, mb->vertex_count, mb->triangle_count);
    return SIZE_MAX;
  }
  wvert *vb = world_vertices(base), *ve = world_vertices(enc);
  uint32_t *map = malloc(me->vertex_count * sizeof *map);
  char *hit = calloc(mb->vertex_count, 1);
  size_t bad = 0, dup = 0;
  double worst[3] = {0, 0, 0};
  for (uint32_t i = 0; i < me->vertex_count; i++) {
    double best = INFINITY;
    uint32_t bi = 0;
    double bd[3] = {0, 0, 0};
    for (uint32_t j = 0; j < mb->vertex_count; j++) {
      double d[3] = {0, 0, 0};
      for (int k = 0; k < 3; k++) d[0] = fmax(d[0], fabs(ve[i].p[k] - vb[j].p[k]));
      for (int k = 0; k < 3; k++) d[1] = fmax(d[1], fabs(ve[i].n[k] - vb[j].n[k]));
      for (int k = 0; k < 2; k++) d[2] = fmax(d[2], fabs(ve[i].uv[k] - vb[j].uv[k]));
      double score = d[0] / tol_p + d[1] / tol_n + d[2] / tol_uv;
      if (score < best) best = score, bi = j, memcpy(bd, d, sizeof bd);
    }
    map[i] = bi;
    if (bd[0] > tol_p || bd[1] > tol_n || bd[2] > tol_uv) bad++;
    for (int k = 0; k < 3; k++) worst[k] = fmax(worst[k], bd[k]);
    if (hit[bi]++) dup++;
  }
  printf("%s: %zu vertices beyond tolerance, %zu mapped twice; worst |dp| %.3g (tol %.3g), |dn| %.3g (tol %.3g), |duv| %.3g (tol %.3g)\n", what, bad, dup, worst[0], tol_p,
         worst[1], tol_n, worst[2], tol_uv);
  uint32_t *tb = malloc(3 * mb->triangle_count * sizeof *tb);
  for (uint32_t t = 0; t < mb->triangle_count; t++) canonical_tri(mb->indices + 3 * t, tb + 3 * t);
  qsort(tb, mb->triangle_count, 3 * sizeof *tb, cmp_tri);
  size_t missing = 0;
  for (uint32_t t = 0; t < me->triangle_count; t++) {
    uint32_t m3[3] = {map[me->indices[3 * t]], map[me->indices[3 * t + 1]], map[me->indices[3 * t + 2]]}, c[3];
    canonical_tri(m3, c);
    if (!bsearch(c, tb, mb->triangle_count, 3 * sizeof *tb, cmp_tri)) missing++;
  }
  printf("%s: %zu of %u triangles are not triangles of the plain file\n", what, missing, me->triangle_count);
  free(tb), free(map), free(hit), free(vb), free(ve);
  return bad + dup + missing;
}

/* Tolerances from the encoders' bit depths (make_web.py): a quantity
 * quantised to b bits over a range r is off by at most r / (2^b - 1) / 2;
 * one full step is allowed. The sphere spans 1.6 on each axis. Octahedral
 * normals with b-bit components are off by at most about 2 / (2^b - 1) per
 * component; two steps are allowed. */
static double step(double range, int bits) { return range / (double)((1 << bits) - 1); }

static void check_geometry(void) {
  iris_scene *base = load_ok("web-base.glb");
  struct {
    const char *file;
    int pos_bits, normal_bits, uv_bits;
  } enc[] = {
      {"web-draco.glb", 14, 10, 12},        /* gltf-transform draco defaults */
      {"web-meshopt.glb", 14, 8, 12},       /* gltf-transform meshopt: normals stored as int8 (OCTAHEDRAL) */
      {"web-gltfpack.glb", 14, 8, 12},      /* gltfpack -cc defaults (-vp 14 -vn 8 -vt 12) */
      {"web-gltfpack-fallback.glb", 14, 8, 12},
  };
  for (size_t i = 0; i < sizeof enc / sizeof *enc; i++) {
    iris_scene *s = load_ok(enc[i].file);
    size_t problems = compare_geometry(enc[i].file, base, s, step(1.6, enc[i].pos_bits),
                                       4.0 * step(1.0, enc[i].normal_bits), step(1.0, enc[i].uv_bits));
    EXPECT(problems == 0, "%s: %zu vertices/triangles differ from the plain file (above)", enc[i].file, problems);
    iris_scene_destroy(s);
  }
  /* The tolerances are tight enough to see a wrong decode: the plain sphere
   * compared with itself shifted by one position step fails. */
  iris_scene *shifted = load_ok("web-base.glb");
  if (shifted) {
    shifted->meshes[0].positions[0] += 3.0f * (float)step(1.6, 14);
    CHECK(compare_geometry("self-check, one vertex moved 3 steps", base, shifted, step(1.6, 14), 1, 1) == 1);
  }
  iris_scene_destroy(shifted);

  /* meshopt is lossless on the data it is given: the decoded views equal the
   * uncompressed fallback buffer bit for bit (same file with the extension removed). */
  iris_scene *a = load_ok("web-gltfpack-fallback.glb"), *b = load_ok("web-gltfpack-nomeshopt.glb");
  if (a && b && EXPECT(a->mesh_count == 1 && b->mesh_count == 1, "mesh counts")) {
    const iris_mesh *ma = &a->meshes[0], *mb = &b->meshes[0];
    CHECK_EQ_INT(ma->vertex_count, mb->vertex_count);
    CHECK_EQ_INT(ma->triangle_count, mb->triangle_count);
    if (ma->vertex_count == mb->vertex_count && ma->triangle_count == mb->triangle_count) {
      CHECK(!memcmp(ma->positions, mb->positions, 12 * (size_t)ma->vertex_count));
      CHECK(!memcmp(ma->uvs, mb->uvs, 8 * (size_t)ma->vertex_count));
      /* Not the normals: gltfpack 0.18 writes the OCTAHEDRAL filter's encoded
       * input (z = 127) to the fallback buffer, not the filtered values (the
       * decoded normals match the plain file above). meshopt's index codec may
       * rotate a triangle's vertices: the same triangles, same orientation. */
      uint32_t *ta = malloc(12 * (size_t)ma->triangle_count), *tb = malloc(12 * (size_t)ma->triangle_count);
      for (uint32_t t = 0; t < ma->triangle_count; t++) {
        canonical_tri(ma->indices + 3 * t, ta + 3 * t);
        canonical_tri(mb->indices + 3 * t, tb + 3 * t);
      }
      qsort(ta, ma->triangle_count, 12, cmp_tri);
      qsort(tb, ma->triangle_count, 12, cmp_tri);
      CHECK(!memcmp(ta, tb, 12 * (size_t)ma->triangle_count));
      free(ta), free(tb);
    }
  }
  iris_scene_destroy(a), iris_scene_destroy(b), iris_scene_destroy(base);
  /* The fallback buffer is never read: the file imports from memory, where
   * external files (its fallback .bin) cannot be opened at all. */
  char path[1024];
  snprintf(path, sizeof path, "%s/web-gltfpack-fallback.glb", IRIS_GLTF_TEST_DATA);
  FILE *fp = fopen(path, "rb");
  static char data[1 << 16];
  size_t n = fp ? fread(data, 1, sizeof data, fp) : 0;
  if (fp) fclose(fp);
  iris_import_options o = iris_import_options_default();
  iris_error e;
  iris_error_clear(&e);
  iris_scene *m = NULL;
  CHECK_OK(iris_import_gltf_memory(data, n, NULL, &o, &m, &e), &e);
  CHECK(m && m->meshes[0].triangle_count == 352);
  iris_scene_destroy(m);
}

/* ---- refusals ------------------------------------------------------------- */

static void expect_refused(const char *name, const char *element, const char *words) {
  char msg[1400] = "", path[1024];
  snprintf(path, sizeof path, "%s/%s", IRIS_GLTF_TEST_DATA, name);
  iris_status st;
  iris_scene *s = load(name, &st, msg, sizeof msg);
  EXPECT(st != IRIS_OK && !s, "%s was accepted", name);
  EXPECT(strstr(msg, path) == msg && !strchr(msg, '\n') && strstr(msg, element) && strstr(msg, words),
         "%s: expected one line naming the file, '%s' and '%s': %s", name, element, words, msg);
  printf("refused: %s\n", msg);
  iris_scene_destroy(s);
}

static void check_refusals(void) {
  expect_refused("bad-draco-count.glb", "mesh 0 primitive 0", "declares 218 elements");
  expect_refused("bad-draco-truncated.glb", "mesh 0 primitive 0", "Draco decoding failed");
  expect_refused("bad-draco-header.glb", "mesh 0 primitive 0", "not Draco data");
  expect_refused("bad-draco-attribute-id.glb", "mesh 0 primitive 0", "Draco id 7");
  expect_refused("bad-draco-indices.glb", "mesh 0 primitive 0", "1053 indices");
  expect_refused("bad-draco-type.glb", "mesh 0 primitive 0", "declares VEC3");
  expect_refused("bad-meshopt-truncated.glb", "bufferView 3", "corrupt or truncated");
  expect_refused("bad-meshopt-count.glb", "bufferView 2", "count 1059");
  expect_refused("bad-meshopt-corrupt.glb", "bufferView 2", "corrupt or truncated");
  expect_refused("bad-meshopt-filter.glb", "bufferView 3", "QUATERNION");
  expect_refused("bad-meshopt-mode.glb", "bufferView 2", "unknown mode");
  expect_refused("basisu-required.gltf", "extensionsRequired", "KHR_texture_basisu");
  /* Every cut of a compressed file is refused in one line or imports (a cut
   * GLB fails its container check; this covers the decoders' own bounds when
   * the cut is repaired in the header: the data simply ends early). */
  const char *files[] = {"web-draco.glb", "web-meshopt.glb"};
  for (size_t f = 0; f < 2; f++) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", IRIS_GLTF_TEST_DATA, files[f]);
    FILE *fp = fopen(path, "rb");
    if (!EXPECT(fp != NULL, "cannot open %s", path)) continue;
    static char data[1 << 16];
    size_t n = fread(data, 1, sizeof data, fp);
    fclose(fp);
    size_t refused = 0;
    for (size_t cut = 0; cut < n; cut += 7) {
      /* Zero the tail of the BIN chunk from `cut` on (the lengths stay valid). */
      static char copy[1 << 16];
      memcpy(copy, data, n);
      uint32_t jl;
      memcpy(&jl, copy + 12, 4);
      if (cut < 28 + (size_t)jl) continue;
      memset(copy + cut, 0, n - cut);
      iris_import_options o = iris_import_options_default();
      iris_error e;
      iris_error_clear(&e);
      iris_scene *s = NULL;
      iris_status st = iris_import_gltf_memory(copy, n, "cut.glb", &o, &s, &e);
      char msg[1400];
      iris_error_format(&e, msg, sizeof msg);
      if (st != IRIS_OK) {
        refused++;
        EXPECT(!s && !strchr(msg, '\n') && strstr(msg, "cut.glb") == msg, "%s zeroed from %zu: %s", files[f], cut, msg);
      }
      iris_scene_destroy(s);
    }
    printf("%s: %zu of the zeroed tails refused\n", files[f], refused);
    CHECK(refused > 0);
  }
}

/* ---- textures ------------------------------------------------------------- */

static bool decode_texture(const iris_scene *s, size_t i, iris_ldr_image *img) {
  iris_error e;
  iris_error_clear(&e);
  memset(img, 0, sizeof *img);
  if (!s || i >= s->texture_count || !s->textures[i].data) return false;
  return iris_ldr_load_memory(s->textures[i].data, s->textures[i].data_size, "texture", img, &e) == IRIS_OK;
}

/* Compares the scene's textures with the plain file's pixel by pixel: the
 * largest channel difference and the PSNR over RGBA. */
static void compare_textures(const char *what, const iris_scene *base, const iris_scene *enc, int max_diff,
                             double min_psnr) {
  if (!EXPECT(base && enc && enc->texture_count == base->texture_count && enc->texture_count == 2,
              "%s: %zu textures", what, enc ? enc->texture_count : 0))
    return;
  for (size_t t = 0; t < 2; t++) {
    iris_ldr_image a, b;
    bool ok = decode_texture(base, t, &a) & decode_texture(enc, t, &b);
    CHECK_EQ_STR(enc->textures[t].mime, "image/png");
    if (EXPECT(ok && a.width == b.width && a.height == b.height, "%s texture %zu: not decoded or sizes differ", what, t)) {
      int worst = 0;
      double se = 0;
      size_t n = 4 * (size_t)a.width * (size_t)a.height;
      for (size_t k = 0; k < n; k++) {
        int d = abs((int)a.rgba[k] - (int)b.rgba[k]);
        worst = d > worst ? d : worst;
        se += (double)d * d;
      }
      double psnr = se > 0 ? 10 * log10(255.0 * 255.0 * (double)n / se) : INFINITY;
      printf("%s texture %zu: %dx%d, largest difference %d, PSNR %.1f dB\n", what, t, b.width, b.height, worst, psnr);
      EXPECT(worst <= max_diff && psnr >= min_psnr, "%s texture %zu: largest difference %d (max %d), PSNR %.1f (min %.1f)",
             what, t, worst, max_diff, psnr, min_psnr);
    }
    iris_ldr_destroy(&a), iris_ldr_destroy(&b);
  }
}

static void check_textures(void) {
  iris_scene *base = load_ok("web-base.glb");
  /* Lossless WebP (cwebp -lossless -exact): the same pixels, RGBA and RGB. */
  iris_scene *s = load_ok("web-webp-lossless.glb");
  compare_textures("web-webp-lossless.glb", base, s, 0, INFINITY);
  iris_scene_destroy(s);
  /* Lossy (cwebp -q 90, 4:2:0 chroma): close, not equal. Measured on these
   * 32x32 gradients: largest differences 8 and 15, PSNR 41.9 and 39.5 dB;
   * the bounds leave margin for other libwebp versions yet fail a wrong
   * channel order or a lost alpha (differences of 100+). */
  s = load_ok("web-webp-lossy.glb");
  compare_textures("web-webp-lossy.glb", base, s, 32, 35.0);
  iris_scene *lossy = s;
  /* Used, not required, with PNG fallbacks: the WebP is preferred (it decodes):
   * the textures are the lossy file's, bit for bit. */
  s = load_ok("web-webp-fallback.glb");
  if (s && lossy && EXPECT(s->texture_count == 2 && lossy->texture_count == 2, "webp-fallback textures"))
    for (size_t t = 0; t < 2; t++)
      CHECK(s->textures[t].data_size == lossy->textures[t].data_size &&
            !memcmp(s->textures[t].data, lossy->textures[t].data, s->textures[t].data_size));
  iris_scene_destroy(s);
  /* A WebP that does not decode, with a PNG fallback: the PNG (the plain file's bytes). */
  s = load_ok("webp-corrupt-fallback.glb");
  if (s && base && EXPECT(s->texture_count == 2, "webp-corrupt-fallback textures")) {
    CHECK(s->textures[0].data_size == base->textures[0].data_size &&
          !memcmp(s->textures[0].data, base->textures[0].data, s->textures[0].data_size));
  }
  iris_scene_destroy(s);
  iris_scene_destroy(lossy);
  /* Without a fallback a broken or lying WebP is refused, naming the image. */
  expect_refused("bad-webp-truncated.glb", "image 0", "WebP decoding failed");
  expect_refused("bad-webp-dims.glb", "image 0", "16384x16384");
  /* KHR_texture_basisu with a PNG fallback: the fallback is used. */
  s = load_ok("basisu-fallback.gltf");
  if (s && EXPECT(s->texture_count == 1, "basisu-fallback: %zu textures", s->texture_count))
    CHECK_EQ_STR(s->textures[0].mime, "image/png");
  iris_scene_destroy(s);
  iris_scene_destroy(base);
}

/* ---- rendering ------------------------------------------------------------- */

/* A lossless encoding renders the same image: the plain file and its lossless
 * WebP version (same geometry, textures with the same pixels), under a white
 * sky with a camera on +z, 32 x 32 at 8 spp with the same seed: equal pixel
 * for pixel (the render is deterministic). The lossy one differs (the test can
 * tell textures apart). */
static bool render_file(const char *name, iris_vec3 *pix, int w) {
  iris_scene *s = load_ok(name);
  if (!s) return false;
  s->has_environment = true;
  s->environment[0] = s->environment[1] = s->environment[2] = 1.0f;
  iris_camera cam;
  memset(&cam, 0, sizeof cam);
  cam.name = iris_strdup("front");
  cam.to_world = iris_mat4_identity();
  cam.to_world.m[0][3] = 0.1f, cam.to_world.m[1][3] = -0.2f, cam.to_world.m[2][3] = 4.0f;
  cam.yfov = 0.5f;
  cam.aspect = 1.0f;
  iris_scene_add_camera(s, &cam);
  iris_render_params p = iris_test_params(w, w, 8, IRIS_METHOD_MIS, 5);
  bool ok = CHECK(iris_test_render_pixels(s, &p, pix));
  iris_scene_destroy(s);
  return ok;
}

static void check_render(void) {
  enum { R = 32 };
  static iris_vec3 a[R * R], b[R * R], c[R * R];
  if (!render_file("web-base.glb", a, R) || !render_file("web-webp-lossless.glb", b, R) ||
      !render_file("web-webp-lossy.glb", c, R))
    return;
  size_t same = 0, same_lossy = 0;
  for (int i = 0; i < R * R; i++) {
    same += a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z;
    same_lossy += a[i].x == c[i].x && a[i].y == c[i].y && a[i].z == c[i].z;
  }
  printf("lossless WebP: %zu of %d pixels equal to the PNG render; lossy: %zu\n", same, R * R, same_lossy);
  CHECK(same == (size_t)R * R);
  CHECK(same_lossy < (size_t)R * R);
}

/* ---- meshopt filters -------------------------------------------------------- */

/* Each filter of importers/meshopt.c against libmeshoptimizer's own encoder:
 * random unit vectors (OCTAHEDRAL, 8 and 16 bits), random unit quaternions
 * (QUATERNION, 12 bits) and random floats over six decades (EXPONENTIAL, 15-bit
 * mantissa) go through encodeFilter + encodeVertexBuffer and back through
 * iris_meshopt_decode; the error stays within the bit depth. A cut stream fails. */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double rnd(void) {
  rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
  return (double)(rng_state >> 11) / 9007199254740992.0;
}

static void check_filters(void) {
  enum { N = 500 };
  static float in[4 * N], out_f[4 * N];
  static uint8_t filtered[8 * N], encoded[16 * 8 * N + 1024], decoded[8 * N];
  for (int kind = 0; kind < 4; kind++) {
    const int bits = kind == 0 ? 8 : kind == 1 ? 16 : kind == 2 ? 12 : 15;
    const size_t stride = kind == 0 ? 4 : 8;
    const iris_meshopt_filter filter =
        kind < 2 ? IRIS_MESHOPT_OCTAHEDRAL : kind == 2 ? IRIS_MESHOPT_QUATERNION : IRIS_MESHOPT_EXPONENTIAL;
    const int comps = kind == 3 ? 2 : 4; /* EXPONENTIAL: two floats per 8-byte element */
    for (int i = 0; i < N; i++) {
      double v[4], l = 0;
      for (int k = 0; k < 4; k++) v[k] = 2 * rnd() - 1, l += v[k] * v[k];
      if (kind < 2) l -= v[3] * v[3], v[3] = 0;
      for (int k = 0; k < 4; k++) in[4 * i + k] = (float)(kind == 3 ? v[k] * pow(10.0, 6 * rnd() - 3) : v[k] / sqrt(l));
      if (kind == 3) in[2 * i] = in[4 * i], in[2 * i + 1] = in[4 * i + 1];
    }
    if (kind < 2) meshopt_encodeFilterOct(filtered, N, stride, bits, in);
    else if (kind == 2) meshopt_encodeFilterQuat(filtered, N, stride, bits, in);
    else meshopt_encodeFilterExp(filtered, N, stride, bits, in);
    size_t size = meshopt_encodeVertexBuffer(encoded, sizeof encoded, filtered, N, stride);
    CHECK(iris_meshopt_check(N, stride, IRIS_MESHOPT_ATTRIBUTES, filter) == NULL);
    if (!CHECK(size > 0 && iris_meshopt_decode(encoded, size, N, stride, IRIS_MESHOPT_ATTRIBUTES, filter, decoded)))
      continue;
    CHECK(!iris_meshopt_decode(encoded, size / 2, N, stride, IRIS_MESHOPT_ATTRIBUTES, filter, decoded));
    double worst = 0;
    for (int i = 0; i < N; i++) {
      double q[4] = {0, 0, 0, 0};
      for (int k = 0; k < comps; k++) {
        if (kind == 0) q[k] = ((const int8_t *)decoded)[4 * i + k] / 127.0;
        else if (kind < 3) q[k] = ((const int16_t *)decoded)[4 * i + k] / 32767.0;
        else memcpy(&out_f[k], decoded + 8 * (size_t)i + 4 * (size_t)k, 4), q[k] = out_f[k];
      }
      /* a quaternion and its negation are the same rotation */
      double dot = 0;
      for (int k = 0; k < 4; k++) dot += q[k] * in[4 * i + k];
      double sign = kind == 2 && dot < 0 ? -1 : 1;
      for (int k = 0; k < comps; k++) {
        const double ref = kind == 3 ? in[2 * i + k] : in[4 * i + k];
        double e = fabs(sign * q[k] - ref);
        if (kind == 3) { /* relative to the element's larger magnitude (the shared exponent) */
          double m = fmax(fabs(in[2 * i]), fabs(in[2 * i + 1]));
          e /= m;
        }
        worst = fmax(worst, e);
      }
    }
    /* Octahedral K-bit: a few steps of 2 / (2^(K-1) - 1) after renormalisation (and
     * the 8/16-bit storage); quaternion K-bit: sqrt(2) / (2^(K-1) - 1) per
     * component plus 16-bit storage; exponential: 2^-(K-1) of the element's scale. */
    const double tol = kind < 2 ? 3.0 / ((1 << (bits - 1)) - 1)
                       : kind == 2 ? 2.0 / ((1 << (bits - 1)) - 1)
                                   : 2.0 / (double)(1 << (bits - 1));
    printf("meshopt filter %s, %d bits: largest error %.3g (tolerance %.3g)\n",
           kind < 2 ? "OCTAHEDRAL" : kind == 2 ? "QUATERNION" : "EXPONENTIAL", bits, worst, tol);
    EXPECT(worst <= tol, "filter kind %d: error %g > %g", kind, worst, tol);
  }
  /* The checks the library would otherwise assert on. */
  CHECK(iris_meshopt_check(3, 6, IRIS_MESHOPT_ATTRIBUTES, IRIS_MESHOPT_NONE) != NULL);
  CHECK(iris_meshopt_check(4, 2, IRIS_MESHOPT_TRIANGLES, IRIS_MESHOPT_NONE) != NULL);
  CHECK(iris_meshopt_check(3, 4, IRIS_MESHOPT_INDICES, IRIS_MESHOPT_OCTAHEDRAL) != NULL);
  CHECK(iris_meshopt_check(3, 12, IRIS_MESHOPT_ATTRIBUTES, IRIS_MESHOPT_OCTAHEDRAL) != NULL);
  CHECK(iris_meshopt_check(0, 4, IRIS_MESHOPT_ATTRIBUTES, IRIS_MESHOPT_NONE) != NULL);
  CHECK(iris_meshopt_check(3, 4, IRIS_MESHOPT_TRIANGLES, IRIS_MESHOPT_NONE) == NULL);
}

int main(int argc, char **argv) {
  iris_log_set_level(IRIS_LOG_WARN);
  const char *part = argc > 1 ? argv[1] : "all";
  if (!strcmp(part, "geometry") || !strcmp(part, "all")) check_geometry();
  if (!strcmp(part, "refusals") || !strcmp(part, "all")) check_refusals();
  if (!strcmp(part, "textures") || !strcmp(part, "all")) check_textures();
  if (!strcmp(part, "filters") || !strcmp(part, "all")) check_filters();
  if (!strcmp(part, "render") || !strcmp(part, "all")) check_render();
  return TEST_SUMMARY();
}
