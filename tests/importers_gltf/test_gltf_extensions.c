/* glTF importer tests of the extensions and derived data with checks of their
 * own: EXT_mesh_gpu_instancing, generated tangents against supplied ones and on
 * mirrored uvs, KHR_materials_anisotropy and KHR_materials_dispersion. Part of
 * test_importers_gltf (main and the shared helpers: test_gltf.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/fileio.h"
#include "core/log.h"
#include "importers/import.h"
#include "importers/tangents.h"
#include "test_gltf.h"

/* ---- EXT_mesh_gpu_instancing ----------------------------------------------- */

/* One triangle placed by EXT_mesh_gpu_instancing (2 instances) against the
 * same TRS in two plain nodes: the same mesh once, the same placements; and
 * malformed attributes refused in one line naming the node. */
static char *make_instanced(const char *nodes, const char *extra_accessors) {
  float bin[35];
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float t[6] = {1, 2, 3, -4, 0.5f, 0};
  const float r[8] = {0, 0.38268343f, 0, 0.92387953f, 0.5f, 0.5f, 0.5f, 0.5f};
  const float sc[6] = {1, 2, 0.5f, -1, 1, 1};
  memcpy(bin, tri, sizeof tri);
  memcpy(bin + 9, t, sizeof t);
  memcpy(bin + 15, r, sizeof r);
  memcpy(bin + 23, sc, sizeof sc);
  const float nan_t[6] = {0, 0, 0, NAN, 0, 0};
  memcpy(bin + 29, nan_t, sizeof nan_t);
  char b64[256];
  base64((const uint8_t *)bin, sizeof bin, b64);
  size_t n = strlen(nodes) + strlen(extra_accessors) + 2048;
  char *j = malloc(n);
  snprintf(j, n,
           "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],"
           "\"buffers\":[{\"byteLength\":140,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
           "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":32},{\"buffer\":0,\"byteOffset\":92,\"byteLength\":24},"
           "{\"buffer\":0,\"byteOffset\":116,\"byteLength\":24}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
           "{\"bufferView\":1,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"VEC4\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
           "{\"bufferView\":4,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}%s],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"nodes\":[%s],\"scenes\":[{\"nodes\":[0%s]}],\"scene\":0}",
           b64, extra_accessors, nodes, strstr(nodes, "},{") ? ",1" : "");
  return j;
}

void check_gpu_instancing(void) {
  iris_import_options o = options();
  char msg[1400];
  iris_scene *a = NULL, *b = NULL;
  const char *ext = "\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":";
  char nodes[1024];
  snprintf(nodes, sizeof nodes,
           "{\"mesh\":0,\"translation\":[0,1,0],%s{\"TRANSLATION\":1,\"ROTATION\":2,\"SCALE\":3}}}}", ext);
  char *j = make_instanced(nodes, "");
  iris_status st = import_text(j, &o, &a, msg, sizeof msg);
  free(j);
  EXPECT(st == IRIS_OK, "EXT_mesh_gpu_instancing: %s", msg);
  /* the same placements as nodes: a parent at (0, 1, 0) with two children */
  j = make_instanced("{\"translation\":[0,1,0],\"children\":[1,2]},"
                     "{\"mesh\":0,\"translation\":[1,2,3],\"rotation\":[0,0.38268343,0,0.92387953],\"scale\":[1,2,0.5]},"
                     "{\"mesh\":0,\"translation\":[-4,0.5,0],\"rotation\":[0.5,0.5,0.5,0.5],\"scale\":[-1,1,1]}",
                     "");
  /* scenes lists node 0 and (wrongly) 1 when there are several nodes: keep only the root */
  char *fix = strstr(j, "\"nodes\":[0,1]");
  if (fix) memcpy(fix, "\"nodes\":[0]  ", 13);
  st = import_text(j, &o, &b, msg, sizeof msg);
  free(j);
  EXPECT(st == IRIS_OK, "nodes: %s", msg);
  if (a && b) {
    EXPECT(a->mesh_count == 1 && a->instance_count == 2, "EXT: %zu meshes, %zu instances", a->mesh_count,
           a->instance_count);
    EXPECT(b->mesh_count == 1 && b->instance_count == 2, "nodes: %zu meshes, %zu instances", b->mesh_count,
           b->instance_count);
    double worst = 0;
    for (size_t i = 0; i < 2 && i < a->instance_count && i < b->instance_count; i++)
      for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
          worst = fmax(worst, fabs((double)a->instances[i].transform.m[r][c] - b->instances[i].transform.m[r][c]));
    EXPECT(worst < 1e-6, "EXT vs nodes: transforms differ by %g", worst);
    EXPECT(fabs(a->instances[0].transform.m[1][3] - 3.0f) < 1e-6, "translation composed with the node: y %g",
           (double)a->instances[0].transform.m[1][3]);
    EXPECT(iris_mat4_det3(&a->instances[1].transform) < 0, "negative scale kept");
  }
  iris_scene_destroy(a);
  iris_scene_destroy(b);

  static const char *const bad[][3] = {
      {"{\"TRANSLATION\":1,\"SCALE\":5}", ",{\"bufferView\":3,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}",
       "node 0 EXT_mesh_gpu_instancing SCALE: accessor 5 has 1 elements, the other attributes 2"},
      {"{\"TRANSLATION\":2}", "", "TRANSLATION: accessor 2 must be VEC3"},
      {"{\"TRANSLATION\":4}", "", "TRANSLATION: instance 1 has a non-finite value"},
      {"{\"ROTATION\":5}", ",{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,\"count\":2,\"type\":\"VEC4\"}",
       "ROTATION: accessor 5 has componentType 5121"},
      {"{\"SCALE\":9}", "", "SCALE accessor 9 does not exist"},
      {"{\"TRANSLATION\":\"x\"}", "", "TRANSLATION accessor -2147483648 does not exist"},
      {"5", "", "node 0 EXT_mesh_gpu_instancing: is not an object with an \"attributes\" object"},
      {"{\"_ID\":1}", "", "node 0 EXT_mesh_gpu_instancing: has none of TRANSLATION, ROTATION, SCALE"},
      {"{\"ROTATION\":5}", ",{\"componentType\":5126,\"count\":2,\"type\":\"VEC4\"}",
       "instance 0: ROTATION quaternion has zero length"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    snprintf(nodes, sizeof nodes, "{\"mesh\":0,%s%s}}}", ext, bad[i][0]);
    j = make_instanced(nodes, bad[i][1]);
    iris_scene *s = NULL;
    st = import_text(j, &o, &s, msg, sizeof msg);
    EXPECT(st != IRIS_OK && s == NULL && strstr(msg, bad[i][2]) && strncmp(msg, "synthetic.gltf: ", 16) == 0 &&
               !strchr(msg, '\n'),
           "bad gpu instancing %zu: %s", i, msg);
    iris_scene_destroy(s);
    free(j);
  }
}

/* ---- tangents -------------------------------------------------------------- */

static float *dup_floats(const float *a, size_t n) {
  if (!a) return NULL;
  float *r = malloc(n * sizeof(float));
  memcpy(r, a, n * sizeof(float));
  return r;
}

/* Generated tangents (importers/tangents.c) against the TANGENT attribute of
 * models that carry both (exported by tools that use MikkTSpace): the same
 * mesh without its tangents goes through the generator. Per vertex: the angle
 * between the tangents and the agreement of the bitangent sign. */
void check_generated_vs_supplied(const char *rel, double max_median_deg, double min_within_1deg,
                                 double min_sign_agree) {
  char path[1024];
  snprintf(path, sizeof path, "%s/gltf/%s", IRIS_ASSETS, rel);
  iris_scene *s = import_ok(path);
  if (!s) return;
  size_t compared = 0, within = 0, sign_ok = 0;
  double *angles = NULL;
  size_t angles_n = 0;
  for (size_t i = 0; i < s->mesh_count; i++) {
    const iris_mesh *m = &s->meshes[i];
    if (!m->tangents) continue;
    iris_mesh c;
    memset(&c, 0, sizeof c);
    c.owned = true;
    c.vertex_count = m->vertex_count, c.triangle_count = m->triangle_count;
    c.positions = dup_floats(m->positions, 3 * (size_t)m->vertex_count);
    c.normals = dup_floats(m->normals, 3 * (size_t)m->vertex_count);
    c.uvs = dup_floats(m->uvs, 2 * (size_t)m->vertex_count);
    c.indices = malloc(12 * (size_t)m->triangle_count);
    memcpy(c.indices, m->indices, 12 * (size_t)m->triangle_count);
    uint32_t split = 0;
    bool ok = iris_mesh_generate_tangents(&c, 0, &split);
    EXPECT(ok, "%s mesh %zu: generation failed", rel, i);
    if (ok) {
      angles = realloc(angles, (angles_n + 3 * (size_t)m->triangle_count) * sizeof *angles);
      /* compare corner by corner (split vertices are copies of an original) */
      for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++) {
        const float *a = m->tangents + 4 * (size_t)m->indices[k], *b = c.tangents + 4 * (size_t)c.indices[k];
        double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
        double deg = acos(d > 1 ? 1 : d < -1 ? -1 : d) * 180.0 / 3.14159265358979;
        angles[angles_n++] = deg;
        compared++;
        within += deg < 1.0;
        sign_ok += a[3] == b[3];
      }
    }
    free(c.positions), free(c.normals), free(c.uvs), free(c.indices), free(c.tangents), free(c.uvs1),
        free(c.colors);
  }
  EXPECT(compared > 0, "%s: no mesh with TANGENT and a normal map", rel);
  if (compared) {
    for (size_t gap = angles_n / 2; gap > 0; gap /= 2) /* shell sort */
      for (size_t i = gap; i < angles_n; i++)
        for (size_t j = i; j >= gap && angles[j - gap] > angles[j]; j -= gap) {
          double t = angles[j];
          angles[j] = angles[j - gap], angles[j - gap] = t;
        }
    double median = angles[angles_n / 2], p99 = angles[(size_t)(0.99 * (double)(angles_n - 1))];
    printf("%s: %zu corners, median %.3g deg, 99th percentile %.3g deg, %.2f%% within 1 deg, sign agrees %.2f%%\n",
           rel, compared, median, p99, 100.0 * (double)within / (double)compared,
           100.0 * (double)sign_ok / (double)compared);
    EXPECT(median <= max_median_deg, "%s: median angle %g deg", rel, median);
    EXPECT((double)within / (double)compared >= min_within_1deg, "%s: %g within 1 deg", rel,
           (double)within / (double)compared);
    EXPECT((double)sign_ok / (double)compared >= min_sign_agree, "%s: sign agrees %g", rel,
           (double)sign_ok / (double)compared);
  }
  free(angles);
  iris_scene_destroy(s);
}

/* Hand-made: a 2x1 strip of two quads whose uvs mirror at the shared edge
 * (u runs 0 -> 1 -> 0): left faces orientation-preserving (w = +1), right ones
 * mirrored (w = -1); the two seam vertices are split, and every tangent points
 * along +u: +x on the left, -x on the right. */
void check_mirrored_uvs(void) {
  const float pos[18] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0};
  const float uv[12] = {0, 1, 1, 1, 0, 1, 0, 0, 1, 0, 0, 0}; /* glTF v down: y = 1 at v = 0 */
  const uint32_t idx[12] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  iris_mesh m;
  memset(&m, 0, sizeof m);
  m.owned = true;
  m.vertex_count = 6, m.triangle_count = 4;
  m.positions = dup_floats(pos, 18);
  m.uvs = dup_floats(uv, 12);
  m.normals = malloc(18 * sizeof(float));
  for (int v = 0; v < 6; v++) m.normals[3 * v] = 0, m.normals[3 * v + 1] = 0, m.normals[3 * v + 2] = 1;
  m.indices = malloc(sizeof idx);
  memcpy(m.indices, idx, sizeof idx);
  uint32_t split = 0;
  EXPECT(iris_mesh_generate_tangents(&m, 0, &split), "mirror: generation failed");
  EXPECT(split == 2 && m.vertex_count == 8, "mirror: %u vertices split (2 expected)", split);
  if (m.tangents && m.vertex_count == 8) {
    for (uint32_t f = 0; f < 4; f++)
      for (int k = 0; k < 3; k++) {
        const float *t = m.tangents + 4 * m.indices[3 * f + (uint32_t)k];
        float want = f < 2 ? 1.0f : -1.0f; /* tangent x and w alike */
        EXPECT(fabsf(t[0] - want) < 1e-6f && fabsf(t[1]) < 1e-6f && t[3] == want,
               "mirror face %u corner %d: tangent (%g %g %g) w %g", f, k, t[0], t[1], t[2], t[3]);
      }
    /* B = w N x T points up the image (towards v = 0, world +y) on both halves */
    for (uint32_t v = 0; v < 8; v++) {
      const float *t = m.tangents + 4 * v;
      float by = t[3] * t[0]; /* (0,0,1) x (tx,0,0) = (0, tx, 0) */
      EXPECT(by > 0.99f, "mirror vertex %u: bitangent y %g", v, by);
    }
  }
  free(m.positions), free(m.uvs), free(m.normals), free(m.indices), free(m.tangents);
}

/* ---- KHR_materials_anisotropy and KHR_materials_dispersion --------------- */

/* Imports `json` with warnings on, returning what was written to stderr. */
static iris_status import_capture(const char *json, iris_scene **s, char *msg, size_t size, char *warn,
                                  size_t warn_size) {
  iris_import_options o = options();
  fflush(stderr);
  int saved = dup(2);
  FILE *tmp = tmpfile();
  dup2(fileno(tmp), 2);
  iris_log_set_level(IRIS_LOG_WARN);
  iris_status st = import_text(json, &o, s, msg, size);
  iris_log_set_level(IRIS_LOG_QUIET);
  fflush(stderr);
  dup2(saved, 2);
  close(saved);
  rewind(tmp);
  size_t n = fread(warn, 1, warn_size - 1, tmp);
  warn[n] = '\0';
  fclose(tmp);
  return st;
}

/* A quad (strip of quad_pos) with NORMAL (0, 0, 1), TEXCOORD_0 = xy and, as accessor 4,
 * TANGENT (cos 30, sin 30, 0, -1): a tilted frame that generation would not give. */
static char *make_gltf_nuv(const char *rest) {
  float bin[17 + 15 + 10 + 20];
  memcpy(bin, quad_pos, 60);
  uint8_t idx[8] = {0};
  memcpy(idx, strip_idx, 6);
  memcpy(bin + 15, idx, 8);
  for (int v = 0; v < 5; v++) {
    bin[17 + 3 * v] = 0, bin[17 + 3 * v + 1] = 0, bin[17 + 3 * v + 2] = 1;
    bin[32 + 2 * v] = quad_pos[3 * v], bin[32 + 2 * v + 1] = quad_pos[3 * v + 1];
    bin[42 + 4 * v] = 0.8660254f, bin[42 + 4 * v + 1] = 0.5f, bin[42 + 4 * v + 2] = 0, bin[42 + 4 * v + 3] = -1;
  }
  char b64[512];
  base64((const uint8_t *)bin, sizeof bin, b64);
  size_t n = strlen(rest) + 2048;
  char *s = malloc(n);
  snprintf(s, n,
           "{\"asset\":{\"version\":\"2.0\"},"
           "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":60},{\"buffer\":0,\"byteOffset\":60,\"byteLength\":6},"
           "{\"buffer\":0,\"byteOffset\":68,\"byteLength\":60},{\"buffer\":0,\"byteOffset\":128,\"byteLength\":40},"
           "{\"buffer\":0,\"byteOffset\":168,\"byteLength\":80}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":5,\"type\":\"VEC3\"},"
           "{\"bufferView\":1,\"componentType\":5121,\"count\":6,\"type\":\"SCALAR\"},"
           "{\"bufferView\":2,\"componentType\":5126,\"count\":5,\"type\":\"VEC3\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":5,\"type\":\"VEC2\"},"
           "{\"bufferView\":4,\"componentType\":5126,\"count\":5,\"type\":\"VEC4\"}],"
           "%s}",
           sizeof bin, b64, rest);
  return s;
}

void check_anisotropy(void) {
  char msg[1400], warn[4096];
  iris_scene *s = NULL;
  /* Material 0: strength 0.5, rotation 0.25, a texture through texCoord 0 with a
   * transform; material 1: strength 1, untextured; material 2: dispersion. Primitive
   * 0 has NORMAL and uvs (tangents generated), 1 has no NORMAL (isotropic, warned). */
  const char *rest =
      "\"images\":[{\"uri\":\"data:image/png;base64,iVBORw0KGgo=\"}],\"textures\":[{\"source\":0}],"
      "\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":0.5,"
      "\"anisotropyRotation\":0.25,\"anisotropyTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":"
      "{\"rotation\":0.5}}}}}},"
      "{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1}}},"
      "{\"name\":\"prism\",\"extensions\":{\"KHR_materials_dispersion\":{\"dispersion\":0.5}}}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":2,\"TEXCOORD_0\":3},\"indices\":1,"
      "\"mode\":5,\"material\":0},{\"attributes\":{\"POSITION\":0},\"indices\":1,\"mode\":5,\"material\":1},"
      "{\"attributes\":{\"POSITION\":0,\"NORMAL\":2},\"indices\":1,\"mode\":5,\"material\":2},"
      "{\"attributes\":{\"POSITION\":0,\"NORMAL\":2,\"TEXCOORD_0\":3,\"TANGENT\":4},\"indices\":1,\"mode\":5,"
      "\"material\":1}]}],"
      "\"nodes\":[{\"mesh\":0}],"
      "\"extensionsUsed\":[\"KHR_materials_anisotropy\",\"KHR_materials_dispersion\",\"KHR_texture_transform\"]";
  char *j = make_gltf_nuv(rest);
  iris_status st = import_capture(j, &s, msg, sizeof msg, warn, sizeof warn);
  free(j);
  EXPECT(st == IRIS_OK, "anisotropy: %s", msg);
  if (st == IRIS_OK && s->mesh_count == 4) {
    const iris_material *m0 = &s->materials[s->meshes[0].material], *m1 = &s->materials[s->meshes[1].material];
    EXPECT(m0->anisotropy == 0.5f && m0->anisotropy_rotation == 0.25f && m0->anisotropy_texture >= 0,
           "anisotropy: strength %g rotation %g texture %d", (double)m0->anisotropy, (double)m0->anisotropy_rotation,
           (int)m0->anisotropy_texture);
    if (m0->anisotropy_texture >= 0) {
      const iris_texture *t = &s->textures[m0->anisotropy_texture];
      EXPECT(t->uv_set == 0 && t->has_transform && t->rotation == 0.5f, "anisotropyTexture: set %u, transform",
             t->uv_set);
    }
    EXPECT(m1->anisotropy == 1.0f && m1->anisotropy_texture == -1 && m1->anisotropy_rotation == 0.0f,
           "untextured anisotropy: %g", (double)m1->anisotropy);
    EXPECT(s->meshes[0].tangents != NULL, "anisotropic primitive with NORMAL and uvs: tangents generated");
    EXPECT(s->meshes[1].tangents == NULL, "anisotropic primitive without NORMAL: no tangents");
    EXPECT(s->meshes[2].tangents == NULL, "isotropic material: no tangents kept");
    const iris_mesh *k = &s->meshes[3];
    bool kept = k->tangents != NULL;
    for (uint32_t v = 0; kept && v < k->vertex_count; v++)
      kept = fabsf(k->tangents[4 * v] - 0.8660254f) < 1e-6f && fabsf(k->tangents[4 * v + 1] - 0.5f) < 1e-6f &&
             k->tangents[4 * v + 3] == -1.0f;
    EXPECT(kept, "anisotropic primitive with TANGENT (no normal map): the file's tangents kept");
  } else {
    EXPECT(0, "anisotropy: %zu meshes", s ? s->mesh_count : 0);
  }
  EXPECT(strstr(warn, "1 anisotropic primitive(s) have no tangent frame") != NULL,
         "anisotropy without tangents warned: %s", warn);
  EXPECT(strstr(warn, "KHR_materials_dispersion in material(s) 'prism': dispersion is not rendered: the ior alone "
                      "is used") != NULL,
         "dispersion warned, naming the material: %s", warn);
  EXPECT(!strstr(warn, "ignoring unsupported extensions"), "neither listed as unsupported: %s", warn);
  { /* once, however many materials */
    const char *a = strstr(warn, "KHR_materials_dispersion");
    EXPECT(a && !strstr(a + 1, "KHR_materials_dispersion"), "dispersion warned once: %s", warn);
  }
  iris_scene_destroy(s);
  s = NULL;

  /* Out of range or malformed: one line naming the file and the material. */
  const char *bad[][2] = {
      {"\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1.5}}}]",
       "material 0: KHR_materials_anisotropy anisotropyStrength 1.5 is not in [0, 1]"},
      {"\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":-0.25}}}]",
       "material 0: KHR_materials_anisotropy anisotropyStrength -0.25 is not in [0, 1]"},
      {"\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyRotation\":\"x\"}}}]",
       "material 0: KHR_materials_anisotropy: a value has the wrong JSON type"},
      {"\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyRotation\":1e300}}}]",
       "material 0: KHR_materials_anisotropy anisotropyRotation 1e+300 is not a finite float"},
      {"\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyTexture\":{\"index\":3}}}}]",
       "material 0: anisotropyTexture: texture 3 does not exist"},
  };
  iris_import_options o = options();
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    j = make_gltf(bad[i][0]);
    st = import_text(j, &o, &s, msg, sizeof msg);
    EXPECT(st == IRIS_ERR_INVALID && s == NULL && strstr(msg, bad[i][1]) && !strchr(msg, '\n') &&
               strncmp(msg, "synthetic.gltf: ", 16) == 0,
           "anisotropy bad %zu: %s", i, msg);
    free(j);
  }
}
